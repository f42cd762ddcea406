// Shared fixture for tests that use Vulkan: one Context per test program, validation layer on,
// and any message the layer reports during a test fails that test.
#pragma once

#include <sdfcsg/sdfcsg.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace sdfcsg::test {

class GpuEnvironment : public ::testing::Environment {
  public:
    static Context* context() { return context_.get(); }
    static const std::string& error() { return error_; }

    void SetUp() override {
        ContextOptions options;
        options.validation = 1;
        auto created = Context::create(options);
        if (created)
            context_ = std::move(*created);
        else
            error_ = created.error().str();
    }
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

// Every bundled scene, sorted by name.
inline std::vector<std::filesystem::path> bundledScenes() {
    std::vector<std::filesystem::path> paths;
    for (const auto& entry : std::filesystem::directory_iterator(
             std::filesystem::path(SDFCSG_SOURCE_DIR) / "assets/scenes"))
        if (entry.path().extension() == ".json") paths.push_back(entry.path());
    std::sort(paths.begin(), paths.end());
    return paths;
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
