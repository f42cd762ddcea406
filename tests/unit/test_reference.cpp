// docs/scene-format.md's field reference is generated from the node table; keep the copy in step.
#include <sdfcsg/scene.h>

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace {

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

TEST(Reference, DocsEmbedTheGeneratedReference) {
    const std::string page = readFile(SDFCSG_SOURCE_DIR "/docs/scene-format.md");
    const std::string begin = "<!-- BEGIN scene-format-reference -->\n";
    const std::string end = "<!-- END scene-format-reference -->";
    size_t b = page.find(begin), e = page.find(end);
    ASSERT_NE(b, std::string::npos);
    ASSERT_NE(e, std::string::npos);
    std::string embedded = page.substr(b + begin.size(), e - b - begin.size());
    EXPECT_EQ(embedded, "\n" + sdfcsg::sceneFormatReference() + "\n")
        << "docs/scene-format.md is out of date: replace the block between the markers with the "
           "output of 'sdfcsg schema --markdown' (and a blank line on each side).";
}

TEST(Reference, MentionsEveryKindAndParameter) {
    const std::string ref = sdfcsg::sceneFormatReference();
    for (const sdfcsg::KindInfo& kind : sdfcsg::nodeKinds()) {
        EXPECT_NE(ref.find("| `" + std::string(kind.name) + "` |"), std::string::npos) << kind.name;
        for (const sdfcsg::ParamInfo& p : kind.params)
            EXPECT_NE(ref.find("`" + std::string(p.name) + "` ("), std::string::npos) << p.name;
    }
}

} // namespace
