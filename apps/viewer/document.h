// The scene file the viewer shows: loading, saving, and reloading when it changes on disk.
// An invalid file never replaces the scene on screen: the last good scene stays, and the
// errors are kept for the error panel.
#pragma once

#include "history.h"

#include <sdfcsg/error.h>
#include <sdfcsg/scene.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace sdfcsg::viewer {

// What identifies a version of a file without reading it.
struct FileStamp {
    bool exists = false;
    std::filesystem::file_time_type time{};
    uintmax_t size = 0;
    bool operator==(const FileStamp&) const = default;
};
FileStamp stampOf(const std::filesystem::path& path);

// Reports changes of one file, by polling (portable, and a scene file is one stat per poll).
class FileWatcher {
  public:
    FileWatcher() = default;
    explicit FileWatcher(std::filesystem::path path)
        : path_(std::move(path)), seen_(stampOf(path_)) {}
    // True once per change since the last poll (or the last acknowledge).
    bool poll();
    // Takes the file as it is now as seen (after the viewer writes it itself).
    void acknowledge() { seen_ = stampOf(path_); }
    const std::filesystem::path& path() const { return path_; }

  private:
    std::filesystem::path path_;
    FileStamp seen_;
};

// The recent-files list, one path a line: $XDG_CONFIG_HOME/sdfcsg/recent, else
// ~/.config/sdfcsg/recent, from the values of those two variables (null or empty: unset); empty
// when neither is set.
std::filesystem::path recentFilesPath(const char* xdgConfigHome, const char* home);
// Missing or unreadable: an empty list. At most `limit` entries.
std::vector<std::string> loadRecent(const std::filesystem::path& file, size_t limit = 10);
// Written atomically, its folder made as needed; failures are ignored (a convenience only).
void saveRecent(const std::filesystem::path& file, const std::vector<std::string>& recent);

class Document {
  public:
    // Loads a file; on failure the current scene stays, with its path and watcher (a document
    // without a scene watches the broken file instead), and error() holds the problems.
    Status open(const std::filesystem::path& path);
    // Reloads if the file changed on disk, or parses the scene on screen again if a file that
    // its nodes read (filesRead()) did, as one more step; true when something changed (scene or
    // error).
    bool pollReload();
    // Writes the current scene as JSON, atomically, and takes that version as seen.
    Status save(const std::filesystem::path& path);
    Status save() { return save(path_); }
    // Makes a scene from elsewhere (a language model's) the current one, as one undo step; the
    // first scene of a document without a file starts its history instead. The file, if any,
    // stays where save() writes.
    void replace(Scene scene);

    const Scene& scene() const { return history_.current(); }
    History& history() { return history_; }
    const std::filesystem::path& path() const { return path_; }
    // Problems of the last load or reload; cleared by the next load or save that succeeds.
    const std::optional<Error>& error() const { return error_; }
    // True once a scene has loaded; before that scene() is empty.
    bool loaded() const { return loaded_; }
    // Counts every change of scene(), so users can tell whether they are up to date.
    uint64_t version() const { return version_; }
    void touch() { ++version_; }

  private:
    bool pollReads();
    bool reloaded(Result<Scene> scene);

    std::filesystem::path path_;
    FileWatcher watcher_;
    std::vector<FileWatcher> reads_; // the files that the scene's nodes read
    History history_;
    std::optional<Error> error_;
    bool loaded_ = false;
    uint64_t version_ = 0;
};

} // namespace sdfcsg::viewer
