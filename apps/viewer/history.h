// Undo and redo over whole scenes: scenes are small, and a copy per step keeps every step exact.
#pragma once

#include <sdfcsg/scene.h>

#include <cstddef>
#include <string>
#include <vector>

namespace sdfcsg::viewer {

class History {
  public:
    explicit History(Scene initial = {}, size_t limit = 256);

    const Scene& current() const { return states_[index_].scene; }
    // Makes `scene` the current state and drops what could be redone. Steps with the same
    // non-empty mergeKey in a row become one step (a slider drag is undone at once).
    void push(Scene scene, std::string mergeKey = {});
    // Ends merging, so the next push starts a new step even with the same key.
    void endMerge() { merging_ = false; }
    // Forgets every step: after opening or reloading a file.
    void reset(Scene scene);

    bool canUndo() const { return index_ > 0; }
    bool canRedo() const { return index_ + 1 < states_.size(); }
    bool undo();
    bool redo();
    size_t size() const { return states_.size(); }

  private:
    struct State {
        Scene scene;
        std::string mergeKey;
    };
    std::vector<State> states_;
    size_t index_ = 0;
    size_t limit_;
    bool merging_ = false;
};

} // namespace sdfcsg::viewer
