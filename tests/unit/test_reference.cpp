// docs/scene-format.md's field reference is generated from the node table; keep the copy in step.
// The limits the docs state are the code's.
#include <sdfcsg/compile.h>
#include <sdfcsg/nodes.h>
#include <sdfcsg/render.h>
#include <sdfcsg/scene.h>

#include "field/prune.h"
#include "scene/font.h"
#include "scene/parse_util.h"
#include "shared.h"

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

// The line of `page` that starts with `start`; empty where none does.
std::string lineStartingWith(const std::string& page, const std::string& start) {
    std::istringstream in(page);
    for (std::string line; std::getline(in, line);)
        if (line.rfind(start, 0) == 0) return line;
    return {};
}

// 65536 as "65,536", as the docs write counts of four digits or more in prose.
std::string grouped(size_t n) {
    std::string digits = std::to_string(n), out;
    for (size_t i = 0; i < digits.size(); ++i) {
        if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
        out += digits[i];
    }
    return out;
}

// Each documented limit, as the code has it: a change to one without the other fails here.
TEST(Reference, DocumentedLimitsAreTheCodes) {
    using namespace sdfcsg;
    using namespace sdfcsg::detail;
    const std::string robustness = readFile(SDFCSG_SOURCE_DIR "/docs/robustness.md");
    const sdfcsg::Limits limits;
    const size_t mib = size_t(1) << 20;
    const std::vector<std::pair<std::string, std::vector<std::string>>> rows = {
        {"scene file or text", {std::to_string(limits.maxFileBytes / mib) + " MiB"}},
        {"nodes", {"| " + std::to_string(limits.maxNodes) + " "}},
        {"nested operations", {"| " + std::to_string(limits.maxDepth) + " "}},
        {"polygon and text outlines",
         {grouped(kMaxPolygonPoints) + " points per polygon",
          grouped(kMaxTextCharacters) + " characters",
          grouped(kMaxTextSegments) + " segments per text",
          std::to_string(kMaxOutlineWords * 16 / mib) + " MiB of outlines"}},
        {"scene and node names", {"| " + std::to_string(kMaxNameCharacters) + " characters"}},
        {"lights", {"| " + std::to_string(SDFCSG_MAX_LIGHTS) + " "}},
        {"problems reported", {"| " + std::to_string(kMaxProblems) + ", "}},
        {"antialiasing",
         {"1.." + std::to_string(kMaxAntialiasing) + " samples",
          "aa must be in 1.." + std::to_string(kMaxAntialiasing) + "`"}},
        {"inlined evaluation",
         {std::to_string(kInlinedMaxNodes) + " nodes",
          "at most " + std::to_string(kInlinedMaxNodes)}},
        {"work per region",
         {std::to_string(kTapeMinNodes) + " nodes or more",
          std::to_string(kMaxMeanCellInstructions) + " instructions on average",
          "limit of " + std::to_string(kMaxMeanCellInstructions) + " "}},
    };
    for (const auto& [what, values] : rows) {
        const std::string row = lineStartingWith(robustness, "| " + what + " |");
        ASSERT_FALSE(row.empty()) << "docs/robustness.md has no row for " << what;
        for (const std::string& value : values)
            EXPECT_NE(row.find(value), std::string::npos)
                << "docs/robustness.md's row for " << what << " lacks '" << value << "': " << row;
    }
    const std::string vocabulary = readFile(SDFCSG_SOURCE_DIR "/docs/vocabulary.md");
    EXPECT_NE(vocabulary.find("Limits: " + grouped(kMaxPolygonPoints) + " polygon points, " +
                              grouped(kMaxTextCharacters) + " characters and " +
                              grouped(kMaxTextSegments) + " segments per text node"),
              std::string::npos);
    const std::string cli = readFile(SDFCSG_SOURCE_DIR "/docs/cli.md");
    EXPECT_NE(lineStartingWith(cli, "| `--aa N` |").find("(1.." + std::to_string(kMaxAntialiasing)),
              std::string::npos);
    const std::string reference = sceneFormatReference();
    EXPECT_NE(reference.find("at most " + std::to_string(kMaxTextCharacters) + " characters"),
              std::string::npos);
    EXPECT_NE(reference.find("3 to " + std::to_string(kMaxPolygonPoints) + " of them"),
              std::string::npos);
}

} // namespace
