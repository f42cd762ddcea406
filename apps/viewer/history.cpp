#include "history.h"

namespace sdfcsg::viewer {

History::History(Scene initial, size_t limit) : limit_(limit < 2 ? 2 : limit) {
    states_.push_back({std::move(initial), {}});
}

void History::push(Scene scene, std::string mergeKey) {
    states_.resize(index_ + 1);
    if (merging_ && !mergeKey.empty() && states_[index_].mergeKey == mergeKey && index_ > 0) {
        states_[index_].scene = std::move(scene);
        return;
    }
    states_.push_back({std::move(scene), mergeKey});
    if (states_.size() > limit_) states_.erase(states_.begin());
    index_ = states_.size() - 1;
    merging_ = !mergeKey.empty();
}

void History::reset(Scene scene) {
    states_.clear();
    states_.push_back({std::move(scene), {}});
    index_ = 0;
    merging_ = false;
}

bool History::undo() {
    merging_ = false;
    if (!canUndo()) return false;
    --index_;
    return true;
}

bool History::redo() {
    merging_ = false;
    if (!canRedo()) return false;
    ++index_;
    return true;
}

} // namespace sdfcsg::viewer
