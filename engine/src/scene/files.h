// The one rule by which a scene names files (a text node's font today; meshes and images
// tomorrow): where a name resolves, which names a scene may use, and what a problem with the file
// may say. sdfcsg/scene.h (SceneFiles) states the rule for users.
#pragma once

#include "sdfcsg/error.h"
#include "sdfcsg/scene.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace sdfcsg::detail {

// The regular file of at most `maxBytes` that `name` names under `files`. Errors are the reason
// alone, for the caller to place: "no such file", "not a regular file", "larger than N MiB", or,
// for an untrusted scene, "not a file this scene may name" (absolute, "..", outside the folder,
// no folder). A caller turns every one of them into untrustedFileProblem() for an untrusted
// scene.
Result<std::filesystem::path> sceneFile(std::string_view name, const SceneFiles& files,
                                        uintmax_t maxBytes);

// The bytes of `file`, as many as its size when opened (refused over `maxBytes`: "larger than N
// MiB", a file that may have grown since sceneFile() looked), read in one piece.
Result<std::string> readFileBytes(const std::filesystem::path& file, uintmax_t maxBytes);

// What any problem with the file `name` (`what`: "font") says in an untrusted scene:
// "unknown WHAT \"NAME\"" and `hint`, nothing about the file system.
std::string untrustedFileProblem(std::string_view what, std::string_view name,
                                 std::string_view hint);

// What a problem `why` with the file `name` that a node reads (`what`: "image", "mesh") says:
// "cannot load WHAT \"PATH\": WHY", PATH the name joined to the scene's folder; in an untrusted
// scene, untrustedFileProblem()'s text with `hint`.
std::string nodeFileProblem(std::string_view what, std::string_view name, const SceneFiles& files,
                            std::string_view why, std::string_view hint);

} // namespace sdfcsg::detail
