// The README and the pages under docs/ are read by people who cannot ask: every relative link
// must lead to a file and, with an anchor, to a heading there, and every example scene in them
// must load.
#include <sdfcsg/scene.h>

#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const fs::path kRoot = SDFCSG_SOURCE_DIR;

std::string readFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

std::vector<fs::path> documents() {
    std::vector<fs::path> files = {kRoot / "README.md"};
    for (const auto& entry : fs::directory_iterator(kRoot / "docs"))
        if (entry.path().extension() == ".md") files.push_back(entry.path());
    return files;
}

struct Line {
    int number;
    std::string text;
};

// The lines outside fenced code blocks, and the fenced blocks' contents by language.
struct Parsed {
    std::vector<Line> prose;
    std::vector<std::pair<std::string, std::string>> blocks; // language, text
};

Parsed parse(const std::string& text) {
    Parsed parsed;
    std::istringstream in(text);
    std::string line, language, block;
    bool fenced = false;
    for (int number = 1; std::getline(in, line); ++number) {
        if (line.rfind("```", 0) == 0) {
            if (fenced) {
                parsed.blocks.emplace_back(language, block);
            } else {
                language = line.substr(3);
                block.clear();
            }
            fenced = !fenced;
        } else if (fenced) {
            block += line + "\n";
        } else {
            parsed.prose.push_back({number, line});
        }
    }
    return parsed;
}

// The anchors GitHub gives a page's headings: lower case, punctuation dropped, spaces as
// hyphens, "-1", "-2", ... after repeats.
std::set<std::string> anchors(const std::string& text) {
    std::set<std::string> result;
    std::map<std::string, int> seen;
    for (const Line& line : parse(text).prose) {
        size_t level = line.text.find_first_not_of('#');
        if (level == 0 || level == std::string::npos || line.text[level] != ' ') continue;
        std::string slug;
        for (char c : line.text.substr(level + 1)) {
            const unsigned char u = static_cast<unsigned char>(c);
            if (std::isalnum(u))
                slug += char(std::tolower(u));
            else if (c == ' ')
                slug += '-';
            else if (c == '-' || c == '_' || u >= 0x80)
                slug += c;
        }
        const int repeat = seen[slug]++;
        result.insert(repeat == 0 ? slug : slug + "-" + std::to_string(repeat));
    }
    return result;
}

// Link targets of one line: "](target)" outside code spans, without a title.
std::vector<std::string> linkTargets(std::string line) {
    for (size_t open; (open = line.find('`')) != std::string::npos;) {
        size_t close = line.find('`', open + 1);
        if (close == std::string::npos) break;
        line.erase(open, close - open + 1);
    }
    std::vector<std::string> targets;
    for (size_t at = 0; (at = line.find("](", at)) != std::string::npos; at += 2) {
        size_t end = line.find(')', at + 2);
        if (end == std::string::npos) break;
        std::string target = line.substr(at + 2, end - at - 2);
        if (size_t space = target.find(' '); space != std::string::npos) target.resize(space);
        targets.push_back(target);
    }
    return targets;
}

TEST(Docs, EveryLinkLeadsToAFileAndHeading) {
    size_t checked = 0;
    for (const fs::path& document : documents()) {
        const std::string name = fs::relative(document, kRoot).string();
        for (const Line& line : parse(readFile(document)).prose) {
            for (const std::string& target : linkTargets(line.text)) {
                if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0)
                    continue;
                ++checked;
                const size_t hash = target.find('#');
                const std::string file = target.substr(0, hash);
                const fs::path path = file.empty() ? document : document.parent_path() / file;
                const std::string where = name + ":" + std::to_string(line.number) + ": " + target;
                if (!fs::exists(path)) {
                    ADD_FAILURE() << where << ": no such file";
                    continue;
                }
                if (hash == std::string::npos || path.extension() != ".md") continue;
                const std::string anchor = target.substr(hash + 1);
                EXPECT_TRUE(anchors(readFile(path)).contains(anchor))
                    << where << ": no heading with that anchor in " << path.filename().string();
            }
        }
    }
    EXPECT_GT(checked, 20u) << "the link scanner found almost no links";
}

TEST(Docs, ExampleScenesLoad) {
    size_t scenes = 0;
    for (const fs::path& document : documents()) {
        for (const auto& [language, text] : parse(readFile(document)).blocks) {
            if (language != "json" || text.find("\"version\"") == std::string::npos) continue;
            ++scenes;
            auto scene = sdfcsg::parseScene(text, fs::relative(document, kRoot).string());
            if (!scene) ADD_FAILURE() << scene.error().str();
        }
    }
    EXPECT_GT(scenes, 0u);
}

TEST(Docs, AnchorsFollowGitHub) {
    const std::set<std::string> expected = {
        "the-command-line", "generate-edit-eval-prompts", "--simplify", "a_b", "x", "x-1"};
    EXPECT_EQ(anchors("# The command line\n## generate, edit, eval-prompts\n## `--simplify`\n"
                      "```\n# not a heading\n```\n## a_b\n## X\n## x\n"),
              expected);
}

} // namespace
