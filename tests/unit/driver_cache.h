// Mesa's disk cache of machine code, for the tests that look at what lavapipe compiled.
#pragma once

#include "scoped_env.h"

#include <sdfcsg/sdfcsg.h>

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>
#include <utility>

namespace sdfcsg::test {

inline bool onLavapipe(Context& context) {
    return context.deviceName().find("llvmpipe") != std::string::npos;
}

// Mesa's disk cache of machine code in a folder of the test's own, which Mesa makes (only the
// last folder of the path), and the kernels it holds.
class DriverCacheFolder {
  public:
    explicit DriverCacheFolder(std::filesystem::path dir)
        : dir_(std::move(dir)), folder_("MESA_SHADER_CACHE_DIR", dir_.string()),
          on_("MESA_SHADER_CACHE_DISABLE", nullptr) {}
    ~DriverCacheFolder() { clear(); }
    const std::filesystem::path& dir() const { return dir_; }
    void clear() const {
        std::error_code ec;
        std::filesystem::remove_all(dir_, ec);
    }
    size_t kernels() const {
        size_t n = 0;
        std::error_code ec;
        for (const auto& entry : std::filesystem::recursive_directory_iterator(dir_, ec))
            n += entry.is_regular_file() && entry.path().filename() != "index";
        return n;
    }

  private:
    std::filesystem::path dir_;
    detail::ScopedEnv folder_, on_;
};

inline std::filesystem::path testFolder(const std::string& name) {
    return std::filesystem::temp_directory_path() / (name + "-" + std::to_string(::getpid()));
}

} // namespace sdfcsg::test
