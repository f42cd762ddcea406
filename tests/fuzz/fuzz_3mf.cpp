// Fuzz target: bytes -> a 3MF package -> readThreeMf. Input starting "PK" is the package itself;
// any other is its model parts' XML, separated by NUL bytes (which XML cannot hold): the root
// model (3D/3dmodel.model), then 3D/Objects/object_1.model, object_2.model and so on, which the
// root's p:path attributes may name. Whatever the bytes, the answer is Ok with as many finite
// corners as it announced, three a triangle, or an Error with a message. Anything else aborts,
// and libFuzzer keeps the input.
#include "field/read_3mf.h"
#include "io/zip.h"

#include <glm/vec3.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

namespace {

[[noreturn]] void fail(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_3mf: %s\n%s\n", what, detail.c_str());
    std::abort();
}

// Small limits, so that each input is quick: what they guard is the same.
constexpr size_t kMaxTriangles = size_t(1) << 16;
constexpr uint64_t kMaxBytes = uint64_t(16) << 20;

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace sdfcsg::detail;
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    std::string package;
    if (input.starts_with("PK")) {
        package = input;
    } else {
        std::vector<std::string> names;
        std::vector<std::string_view> parts;
        for (std::string_view rest = input;;) {
            const size_t nul = rest.find('\0');
            names.push_back(parts.empty()
                                ? "3D/3dmodel.model"
                                : "3D/Objects/object_" + std::to_string(parts.size()) + ".model");
            parts.push_back(rest.substr(0, nul));
            if (nul == std::string_view::npos) break;
            rest.remove_prefix(nul + 1);
        }
        std::vector<ZipEntry> entries;
        for (size_t k = 0; k < parts.size(); ++k)
            entries.push_back({names[k], parts[k]});
        package = zipArchive(entries).value_or(std::string());
    }
    size_t announced = 0, corners = 0;
    const ThreeMfCorners out{[&](size_t triangles) { announced = triangles; },
                             [&](glm::vec3 p, uint32_t) {
                                 if (!std::isfinite(p.x + p.y + p.z))
                                     fail("a corner that is not finite", "");
                                 ++corners;
                             }};
    const sdfcsg::Status read = readThreeMf(package, out, kMaxTriangles, kMaxBytes, 10.0);
    if (!read) {
        if (read.error().diagnostics.empty() || read.error().diagnostics[0].message.empty())
            fail("an error without a message", "");
        return 0;
    }
    if (announced > kMaxTriangles) fail("more triangles than the limit", "");
    if (corners != 3 * announced)
        fail("corners other than three a triangle announced",
             std::to_string(corners) + " for " + std::to_string(announced));
    return 0;
}
