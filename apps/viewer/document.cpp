#include "document.h"

#include <sdfcsg/io.h>

#include <algorithm>
#include <fstream>
#include <system_error>

namespace sdfcsg::viewer {

FileStamp stampOf(const std::filesystem::path& path) {
    std::error_code ec;
    FileStamp stamp;
    stamp.time = std::filesystem::last_write_time(path, ec);
    if (ec) return {};
    stamp.size = std::filesystem::file_size(path, ec);
    if (ec) return {};
    stamp.exists = true;
    return stamp;
}

bool FileWatcher::poll() {
    if (path_.empty()) return false;
    FileStamp now = stampOf(path_);
    if (now == seen_) return false;
    seen_ = now;
    // A file being replaced is briefly absent; its reappearance is the change to report.
    return now.exists;
}

std::filesystem::path recentFilesPath(const char* xdgConfigHome, const char* home) {
    if (xdgConfigHome && *xdgConfigHome)
        return std::filesystem::path(xdgConfigHome) / "sdfcsg" / "recent";
    if (home && *home) return std::filesystem::path(home) / ".config" / "sdfcsg" / "recent";
    return {};
}

std::vector<std::string> loadRecent(const std::filesystem::path& file, size_t limit) {
    std::vector<std::string> recent;
    if (file.empty()) return recent;
    std::ifstream in(file);
    for (std::string line; recent.size() < limit && std::getline(in, line);)
        if (!line.empty()) recent.push_back(line);
    return recent;
}

void saveRecent(const std::filesystem::path& file, const std::vector<std::string>& recent) {
    if (file.empty()) return;
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    std::string text;
    for (const std::string& r : recent)
        text += r + "\n";
    (void)writeFileAtomic(file, text);
}

Status Document::open(const std::filesystem::path& path) {
    auto scene = loadScene(path);
    // A broken file replaces nothing: with a scene on screen, saving and live reload stay on
    // that scene's file (else Save would write it over the broken one). Without one, the
    // broken file is watched, so fixing it on disk loads it.
    if (!scene) {
        error_ = scene.error();
        ++version_;
        if (!loaded_) {
            path_ = path;
            watcher_ = FileWatcher(path);
        }
        return scene.error();
    }
    path_ = path;
    watcher_ = FileWatcher(path);
    error_.reset();
    history_.reset(std::move(*scene));
    loaded_ = true;
    ++version_;
    return Ok{};
}

bool Document::pollReload() {
    return watcher_.poll() ? reloaded(loadScene(path_)) : pollReads();
}

// A reload is one more step, so an edit made outside can be undone like one made here; one that
// fails keeps the scene on screen, and its errors.
bool Document::reloaded(Result<Scene> scene) {
    ++version_;
    if (!scene) {
        error_ = scene.error();
        return true;
    }
    error_.reset();
    history_.endMerge();
    history_.push(std::move(*scene));
    loaded_ = true;
    return true;
}

// The files are those of the scene on screen, whichever step of its history: a set that
// differs from the last poll's is watched from now on, a change of one of them parses the scene
// again (its JSON names the files; the parse reads them).
bool Document::pollReads() {
    if (!loaded_) return false;
    const std::vector<std::filesystem::path> files = filesRead(scene());
    if (!std::equal(files.begin(), files.end(), reads_.begin(), reads_.end(),
                    [](const auto& file, const FileWatcher& w) { return file == w.path(); })) {
        reads_.clear();
        for (const std::filesystem::path& file : files)
            reads_.emplace_back(file);
        return false;
    }
    bool changed = false;
    for (FileWatcher& read : reads_)
        changed = read.poll() || changed;
    if (!changed) return false;
    ParseOptions options;
    options.files = scene().files;
    return reloaded(parseScene(toJson(scene()), scene().file, options));
}

void Document::replace(Scene scene) {
    if (loaded_) {
        history_.endMerge();
        history_.push(std::move(scene));
    } else {
        history_.reset(std::move(scene));
    }
    loaded_ = true;
    ++version_;
}

Status Document::save(const std::filesystem::path& path) {
    auto written = writeFileAtomic(path, toJson(scene()));
    if (!written) return written;
    error_.reset(); // the file now holds the scene on screen, whatever failed to load before
    if (path != path_) {
        path_ = path;
        watcher_ = FileWatcher(path);
    } else {
        watcher_.acknowledge();
    }
    return Ok{};
}

} // namespace sdfcsg::viewer
