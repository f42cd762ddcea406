// The one place where the library reads the environment (environment.h says when).
#include "gpu/environment.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <string>
#include <string_view>

namespace sdfcsg::detail {

Environment readEnvironment(const std::function<const char*(const char* name)>& lookup) {
    auto variable = [&](const char* name) -> std::string_view {
        const char* value = lookup(name);
        return value ? value : "";
    };
    Environment e;
    if (const std::string_view v = variable("SDFCSG_VALIDATION"); !v.empty())
        e.validation = v == "0" ? 0 : 1;
    e.device = variable("SDFCSG_DEVICE");
    if (const std::string_view dir = variable("SDFCSG_CACHE_DIR"); !dir.empty())
        e.shaderCacheDir = dir == "off" ? std::filesystem::path() : std::filesystem::path(dir);
    else if (const std::string_view xdg = variable("XDG_CACHE_HOME"); !xdg.empty())
        e.shaderCacheDir = std::filesystem::path(xdg) / "sdfcsg";
    else if (const std::string_view home = variable("HOME"); !home.empty())
        e.shaderCacheDir = std::filesystem::path(home) / ".cache" / "sdfcsg";
    if (const std::string size(variable("SDFCSG_CACHE_SIZE")); !size.empty()) {
        char* end = nullptr;
        const double mib = std::strtod(size.c_str(), &end);
        // Up to an exbibyte, which no disk holds: beyond it, the bytes would not fit 64 bits.
        if (end != size.c_str() && *end == '\0' && mib > 0.0 && mib <= double(1ull << 40))
            e.shaderCacheMaxBytes = std::max<uint64_t>(1, uint64_t(mib * double(1 << 20)));
    }
    return e;
}

const Environment& environment() {
    static const Environment e =
        readEnvironment([](const char* name) { return std::getenv(name); });
    return e;
}

bool mesaDiskCacheDisabled() {
    for (const char* name : {"MESA_SHADER_CACHE_DISABLE", "MESA_GLSL_CACHE_DISABLE"}) {
        const char* value = std::getenv(name);
        std::string v = value ? value : "";
        for (char& c : v)
            c = char(std::tolower(static_cast<unsigned char>(c)));
        if (v == "1" || v == "y" || v == "yes" || v == "t" || v == "true") return true;
    }
    return false;
}

} // namespace sdfcsg::detail
