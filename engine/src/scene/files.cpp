// A scene read from a stranger (a language model's answer goes back to the model with its
// problems) must not become a way to ask the file system questions: which paths exist, which are
// folders, how large a file is. Every file a scene names goes through sceneFile(), and the
// callers of an untrusted scene's problems say only that the name is unknown.
#include "scene/files.h"

#include "scene/parse_util.h"
#include "sdfcsg/nodes.h"

#include <algorithm>
#include <fstream>

namespace sdfcsg::detail {

namespace fs = std::filesystem;

namespace {

Error reason(std::string text) {
    return Error::message(ErrorKind::Validation, {}, std::move(text));
}

// Inside `folder` after symbolic links are followed: a link in the folder that points out of it
// would otherwise reach any file.
bool inside(const fs::path& file, const fs::path& folder) {
    std::error_code ec;
    const fs::path real = fs::canonical(file, ec);
    if (ec) return false;
    const fs::path base = fs::canonical(folder, ec);
    if (ec) return false;
    auto r = real.begin();
    for (auto b = base.begin(); b != base.end(); ++b, ++r)
        if (r == real.end() || *r != *b) return false;
    return r != real.end();
}

} // namespace

Result<fs::path> sceneFile(std::string_view name, const SceneFiles& files, uintmax_t maxBytes) {
    const fs::path named(name);
    if (!files.trusted) {
        bool up = false;
        for (const fs::path& part : named)
            up = up || part == "..";
        if (name.empty() || files.folder.empty() || named.is_absolute() || named.has_root_name() ||
            up || name.find('\0') != std::string_view::npos)
            return reason("not a file this scene may name");
    }
    const fs::path file =
        named.is_absolute() || files.folder.empty() ? named : files.folder / named;
    std::error_code ec;
    // Only regular files: a pipe or a device would block or never end.
    if (!fs::is_regular_file(file, ec))
        return reason(fs::exists(file, ec) ? "not a regular file" : "no such file");
    if (!files.trusted && !inside(file, files.folder))
        return reason("not a file this scene may name");
    if (fs::file_size(file, ec) > maxBytes || ec)
        return reason("larger than " + std::to_string(maxBytes >> 20) + " MiB");
    return file;
}

Result<std::string> readFileBytes(const fs::path& file, uintmax_t maxBytes) {
    std::ifstream in(file, std::ios::binary);
    std::error_code ec;
    const uintmax_t size = fs::file_size(file, ec);
    if (!in || ec) return reason("cannot be read");
    if (size > maxBytes) return reason("larger than " + std::to_string(maxBytes >> 20) + " MiB");
    std::string bytes(size_t(size), '\0');
    in.read(bytes.data(), std::streamsize(size));
    if (size_t(in.gcount()) != bytes.size()) return reason("cannot be read");
    return bytes;
}

std::string untrustedFileProblem(std::string_view what, std::string_view name,
                                 std::string_view hint) {
    return "unknown " + std::string(what) + " " + quote(name) + std::string(hint);
}

std::string nodeFileProblem(std::string_view what, std::string_view name, const SceneFiles& files,
                            std::string_view why, std::string_view hint) {
    if (!files.trusted) return untrustedFileProblem(what, name, hint);
    const fs::path named(name);
    const bool joined = !named.is_absolute() && !files.folder.empty();
    return "cannot load " + std::string(what) + " " +
           quote(joined ? (files.folder / named).string() : std::string(name)) + ": " +
           std::string(why);
}

} // namespace sdfcsg::detail

namespace sdfcsg {

std::vector<std::filesystem::path> filesRead(const Scene& scene) {
    std::vector<std::filesystem::path> read;
    for (const Node& node : scene.nodes)
        for (const ParamInfo& param : kindInfo(node.kind).params)
            if (param.type == ValueType::Text && param.unit == "file") {
                const std::filesystem::path named(node.strings[param.slot]);
                std::filesystem::path file = named.is_absolute() || scene.files.folder.empty()
                                                 ? named
                                                 : scene.files.folder / named;
                if (std::find(read.begin(), read.end(), file) == read.end())
                    read.push_back(std::move(file));
            }
    return read;
}

} // namespace sdfcsg
