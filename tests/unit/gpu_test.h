// Shared fixture for tests that use Vulkan: one Context per test process, validation layer on,
// and any message the layer reports during a test fails that test.
#pragma once

#include "scene_build_util.h"

#include <sdfcsg/sdfcsg.h>

#include <gtest/gtest.h>

#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-compare"
#endif
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace sdfcsg::test {

// The context is made by the first GPU test that runs, not at the program's start: ctest runs
// each suite as a process of its own (tests/CMakeLists.txt), and one whose tests need no device
// then pays nothing for it.
class GpuEnvironment : public ::testing::Environment {
  public:
    // Made on the first call; nullptr if that failed, and error() says why (not retried).
    static Context* context() {
        if (!context_ && error_.empty()) {
            ContextOptions options;
            options.validation = 1;
            auto created = Context::create(options);
            if (created)
                context_ = std::move(*created);
            else
                error_ = created.error().str();
        }
        return context_.get();
    }
    static const std::string& error() { return error_; }

    // Before static destruction, while the driver is certainly still loaded.
    void TearDown() override { context_.reset(); }

  private:
    static inline std::unique_ptr<Context> context_;
    static inline std::string error_;
};

inline ::testing::Environment* const kGpuEnvironment =
    ::testing::AddGlobalTestEnvironment(new GpuEnvironment);

class GpuTest : public ::testing::Test {
  protected:
    Context& context() { return *GpuEnvironment::context(); }

    void SetUp() override {
        ASSERT_NE(GpuEnvironment::context(), nullptr)
            << "no Vulkan context: " << GpuEnvironment::error();
        messagesBefore_ = context().validationMessageCount();
    }
    void TearDown() override {
        if (!GpuEnvironment::context()) return;
        EXPECT_EQ(context().validationMessageCount(), messagesBefore_)
            << "the validation layer reported problems during this test (printed on stderr)";
    }

  private:
    uint32_t messagesBefore_ = 0;
};

// Reads a PNG back as RGBA8 (what writePng wrote); nullopt if unreadable.
inline std::optional<Image> readPng(const std::filesystem::path& path) {
    int w = 0, h = 0, n = 0;
    stbi_uc* data = stbi_load(path.string().c_str(), &w, &h, &n, 4);
    if (!data) return std::nullopt;
    Image image{uint32_t(w), uint32_t(h), std::vector<uint8_t>(data, data + size_t(w) * h * 4)};
    stbi_image_free(data);
    return image;
}

// Every bundled scene, sorted by name.
inline std::vector<std::filesystem::path> bundledScenes() {
    return bundledScenePaths();
}

// Test names for TEST_P over scene paths: the file stem.
inline std::string sceneTestName(const ::testing::TestParamInfo<std::filesystem::path>& info) {
    std::string name = info.param.stem().string();
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return name;
}

inline Scene loadOrDie(const std::filesystem::path& path) {
    auto scene = loadScene(path);
    if (!scene) {
        ADD_FAILURE() << scene.error().str();
        return Scene{};
    }
    return *scene;
}

} // namespace sdfcsg::test
