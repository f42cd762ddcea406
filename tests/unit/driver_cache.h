// Mesa's disk cache of machine code, for the tests that look at what lavapipe compiled.
#pragma once

#include "gpu/vk.h"
#include "scoped_env.h"

#include <sdfcsg/sdfcsg.h>

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <mutex>
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
    ScopedEnv folder_, on_;
};

inline std::filesystem::path testFolder(const std::string& name) {
    return std::filesystem::temp_directory_path() / (name + "-" + std::to_string(::getpid()));
}

// Runs `use(context)` on a new context with `options` and the validation layer on, expects no
// message from the layer, and destroys the context, which finishes the driver cache's writes.
template <class Use> void onNewContext(ContextOptions options, Use&& use) {
    options.validation = 1;
    auto ctx = Context::create(options);
    ASSERT_TRUE(ctx) << ctx.error().str();
    use(**ctx);
    EXPECT_EQ((*ctx)->validationMessageCount(), 0u);
}
// The same with the compile helper as given.
template <class Use> void onNewContext(bool helper, Use&& use) {
    ContextOptions options;
    options.compileHelper = helper;
    onNewContext(options, std::forward<Use>(use));
}

// On lavapipe the compile helper compiles some pipelines while the context's device compiles
// others, and Mesa's disk cache hands the machine code over, which works only if the helper's
// pipelines are the ones this device looks up (same SPIR-V, layout, constants and the values
// bound at the first dispatch): otherwise this device compiles them again and caches more
// kernels. Runs `use(context, helper)`, which builds and runs what is tested, on a new context
// without and then with the helper, each time with `cache` empty and no SPIR-V cached, and
// checks that both cached the same kernels, that the helper compiled `helperPipelines`, and that
// the context did not take its hand-over to have failed.
template <class Use>
void expectHelperHandsOver(const DriverCacheFolder& cache, uint32_t helperPipelines, Use&& use) {
    size_t cached[2] = {};
    for (int helper : {0, 1}) {
        SCOPED_TRACE(helper ? "with the helper" : "without the helper");
        cache.clear();
        clearShaderMemoryCache();
        ContextOptions options;
        options.compileHelper = helper;
        options.shaderCacheDir = std::filesystem::path();
        onNewContext(options, [&](Context& ctx) {
            Context::Impl& impl = detail::contextImpl(ctx);
            ASSERT_EQ(impl.helperWanted, bool(helper));
            use(ctx, helper);
            EXPECT_EQ(impl.helperCompiles.load(), helper ? helperPipelines : 0u);
            std::lock_guard lock(impl.helperMutex);
            EXPECT_FALSE(impl.helperFailed) << "the hand-over was taken to fail";
        });
        cached[helper] = cache.kernels();
    }
    EXPECT_GE(cached[0], 2u) << "the driver cached too little in " << cache.dir();
    EXPECT_EQ(cached[1], cached[0]) << "this device compiled the helper's kernels again";
}

} // namespace sdfcsg::test
