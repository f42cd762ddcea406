// sdfcsg generate, edit and eval-prompts: the command-line side of the engine's language model
// client (sdfcsg/generate.h). Settings come from the environment and the flags; the scene is
// validated by the engine before anything is written.
#include "generate.h"

#include "cli.h"

#include <sdfcsg/sdfcsg.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

namespace sdfcsg::app {
namespace {

namespace fs = std::filesystem;

// Positional arguments, and options that take a value (the last one given wins) or not.
struct Args {
    std::vector<std::string> positional;
    std::vector<std::pair<std::string, std::string>> options;
    std::string error;

    bool has(std::string_view name) const {
        return std::any_of(options.begin(), options.end(),
                           [&](const auto& o) { return o.first == name; });
    }
    std::string get(std::string_view name) const {
        for (auto it = options.rbegin(); it != options.rend(); ++it)
            if (it->first == name) return it->second;
        return {};
    }
};

// Flags every command here takes: the endpoint, the repair loop, and recording.
const std::vector<std::string_view> kLlmValued = {"--model",       "--base-url",   "--api",
                                                  "--max-repairs", "--max-tokens", "--timeout",
                                                  "--record",      "--replay"};

Args parseArgs(int argc, char** argv, std::vector<std::string_view> valued,
               std::vector<std::string_view> flags) {
    valued.insert(valued.end(), kLlmValued.begin(), kLlmValued.end());
    flags.insert(flags.end(), {"--help", "-h"});
    auto in = [](const std::vector<std::string_view>& list, std::string_view s) {
        return std::find(list.begin(), list.end(), s) != list.end();
    };
    Args args;
    for (int i = 0; i < argc; ++i) {
        std::string a = argv[i];
        if (a.size() < 2 || a[0] != '-') {
            args.positional.push_back(a);
            continue;
        }
        std::string value;
        if (auto eq = a.find('='); eq != std::string::npos) {
            value = a.substr(eq + 1);
            a.resize(eq);
        } else if (in(valued, a)) {
            if (i + 1 >= argc) {
                args.error = "option " + a + " needs a value";
                return args;
            }
            value = argv[++i];
        }
        if (!in(valued, a) && !in(flags, a)) {
            args.error = "unknown option " + a;
            return args;
        }
        args.options.emplace_back(a, value);
    }
    return args;
}

bool parseNumber(const std::string& s, double lo, double hi, double& out) {
    char* end = nullptr;
    errno = 0;
    double v = std::strtod(s.c_str(), &end);
    if (s.empty() || *end || errno || !(v >= lo && v <= hi)) return false;
    out = v;
    return true;
}

// "1 prompt", "2 prompts".
std::string counted(size_t n, std::string_view noun) {
    return std::to_string(n) + " " + std::string(noun) + (n == 1 ? "" : "s");
}

Result<std::string> readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return Error::message(ErrorKind::Io, path, "cannot read file");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

const char* kLlmOptionsHelp = R"(
Endpoint (OpenAI Chat Completions, or Ollama's native /api/chat):
  --base-url URL     default: SDFCSG_LLM_BASE_URL, OPENAI_BASE_URL, https://api.openai.com/v1
  --model M          default: SDFCSG_LLM_MODEL (gpt-4o-mini on api.openai.com)
  --api openai|ollama  default: SDFCSG_LLM_API, else Ollama when the port is 11434
  The API key comes from SDFCSG_LLM_API_KEY or OPENAI_API_KEY only; it is never printed.
  Proxies: the standard http_proxy, https_proxy and no_proxy variables.
  --max-repairs N    correction rounds after an answer that does not load (default 3)
  --max-tokens N     answer length limit (default 8192)
  --timeout S        seconds per request (default 300)
  --print-prompt     print the conversation's first messages and stop
  --dry-run          print the first request (URL and body) and stop
  --record FILE      write every HTTP exchange to FILE (no headers, so no key)
  --replay FILE      answer from a recording instead of the network
)";

// Applies the shared flags on top of the environment's settings.
std::string configure(const Args& args, GenerateOptions& options) {
    options.llm = llmConfigFromEnvironment();
    if (args.has("--base-url")) options.llm.baseUrl = args.get("--base-url");
    if (args.has("--model")) options.llm.model = args.get("--model");
    if (args.has("--api")) {
        const std::string api = args.get("--api");
        if (api != "openai" && api != "ollama") return "--api expects openai or ollama";
        options.llm.api = api == "openai" ? LlmApi::OpenAI : LlmApi::Ollama;
    }
    double v = 0;
    if (args.has("--max-repairs")) {
        if (!parseNumber(args.get("--max-repairs"), 0, 20, v) || v != std::floor(v))
            return "--max-repairs expects an integer in 0..20";
        options.maxRepairs = int(v);
    }
    if (args.has("--max-tokens")) {
        if (!parseNumber(args.get("--max-tokens"), 256, 1e6, v) || v != std::floor(v))
            return "--max-tokens expects an integer in 256..1000000";
        options.llm.maxTokens = uint32_t(v);
    }
    if (args.has("--timeout")) {
        if (!parseNumber(args.get("--timeout"), 0.1, 86400, v))
            return "--timeout expects seconds in 0.1..86400";
        options.llm.timeoutSeconds = v;
    }
    if (args.has("--record") && args.has("--replay")) return "give --record or --replay, not both";
    return {};
}

// Status lines on stderr; on a terminal, a line that counts the seconds while an answer is
// awaited.
class ProgressPrinter {
  public:
    void operator()(const GenerateProgress& p) {
        if (p.waiting) {
            if (!tty_) return;
            std::fprintf(stderr, "\r  waiting %.0f s ", p.seconds);
            std::fflush(stderr);
            ticking_ = true;
            return;
        }
        clear();
        std::fprintf(stderr, "%s\n", p.message.c_str());
    }
    void clear() {
        if (ticking_) std::fprintf(stderr, "\r%20s\r", "");
        ticking_ = false;
    }
    ~ProgressPrinter() { clear(); }

  private:
    bool tty_ = ::isatty(STDERR_FILENO) != 0;
    bool ticking_ = false;
};

// One Vulkan context for all renders of a command, made on first use. Ctrl-C stops a render.
class Renders {
  public:
    Result<Image> render(const Scene& scene, uint32_t width, uint32_t height) {
        if (!context_) {
            auto context = Context::create();
            if (!context) return context.error();
            context_ = std::move(*context);
        }
        auto renderer = Renderer::create(*context_, scene);
        if (!renderer) return renderer.error();
        RenderOptions options;
        options.width = width;
        options.height = height;
        options.progress = [](float) { return !interrupted(); };
        return (*renderer)->render(options);
    }

  private:
    std::unique_ptr<Context> context_;
};

// --replay and --record around a function that generates.
struct Recording {
    std::vector<HttpExchange> replay, record;
    std::string recordPath;

    Status setUp(const Args& args, GenerateOptions& options) {
        if (args.has("--replay")) {
            auto text = readFile(args.get("--replay"));
            if (!text) return text.error();
            auto parsed = parseRecording(*text, args.get("--replay"));
            if (!parsed) return parsed.error();
            replay = std::move(*parsed);
            options.replay = &replay;
        }
        recordPath = args.get("--record");
        if (!recordPath.empty()) options.record = &record;
        return Ok{};
    }
    Status save() const {
        if (recordPath.empty()) return Ok{};
        return writeFileAtomic(recordPath, recordingToJson(record));
    }
};

void printSummary(const std::string& out, const Generated& g, const GenerateStats& s) {
    std::fprintf(stderr, "%s: %s\n", out.c_str(), generationSummary(g, s).c_str());
    for (const Diagnostic& w : g.warnings)
        std::fprintf(stderr, "warning: %s: %s\n", w.path.c_str(), w.message.c_str());
}

// generate and edit: everything after the request is built.
int generateAndWrite(std::string_view command, std::string_view request, GenerateOptions& options,
                     const Args& args) {
    if (args.has("--print-prompt")) {
        std::printf("[system]\n%s\n[user]\n%s\n", sceneSystemPrompt().c_str(),
                    sceneUserPrompt(request, options.currentScene).c_str());
        return kOk;
    }
    if (args.has("--dry-run")) {
        auto r = firstLlmRequest(request, options);
        if (!r) return fail(r.error());
        std::printf("POST %s\n%s\n\n%s\n", r->shownUrl.c_str(),
                    options.llm.apiKey.empty() ? "(no API key)" : "Authorization: Bearer [hidden]",
                    r->body.c_str());
        return kOk;
    }
    const std::string out = args.get("-o").empty() ? args.get("--output") : args.get("-o");
    if (out.empty()) return usageError(command, "missing -o OUT.json");
    const std::string emit = args.has("--emit") ? args.get("--emit") : "json";
    if (emit != "json" && emit != "python")
        return usageError(command, "--emit expects json or python");

    Recording recording;
    if (auto ready = recording.setUp(args, options); !ready) return fail(ready.error());
    ProgressPrinter printer;
    options.progress = [&printer](const GenerateProgress& p) { printer(p); };
    catchInterrupts();
    options.cancelled = [] { return interrupted(); };
    GenerateStats stats;
    auto generated = generateScene(request, options, &stats);
    printer.clear();
    {
        Finishing finishing;
        // Also when interrupted or failed: the exchanges so far are what a bug report needs.
        if (auto saved = recording.save(); !saved) return fail(saved.error());
        if (!generated) {
            if (generated.error().kind == ErrorKind::Cancelled && interrupted() &&
                !recording.recordPath.empty())
                return stopInterrupted("sdfcsg: interrupted; " + out +
                                       " was not written, the exchanges so far are in " +
                                       recording.recordPath);
            return fail(generated.error());
        }
    }
    // As Python, the program saves the scene beside it by default: chair.py writes chair.json.
    const std::string text =
        emit == "python"
            ? model::toPython(generated->scene,
                              fs::path(out).filename().replace_extension(".json").string())
            : generated->json;
    if (auto written = writeOutput(out, text); !written) return fail(written.error());
    printSummary(out, *generated, stats);
    if (const std::string png = args.get("--render"); !png.empty()) {
        Renders renders;
        auto image = renders.render(generated->scene, 800, 600);
        auto bytes = image ? encodePng(*image, png) : Result<std::string>(image.error());
        Status written = bytes ? writeOutput(png, *bytes) : Status(bytes.error());
        if (!written) return fail(written.error());
    }
    return kOk;
}

const char* kGenerateHelp =
    R"(Usage: sdfcsg generate "PROMPT" -o OUT.json [--render OUT.png] [options]

Asks a language model for a scene that matches PROMPT, validates the answer, and on problems
sends the validator's list back and asks for a correction. Only a scene that loads is written
(atomically); otherwise the problems are printed and the exit code is 1. Cheap geometric
checks (an empty solid, a difference that removes nothing, parts floating apart, absurd
bounds) print warnings. Structured output (a strict JSON Schema) is used where the server
accepts it, else JSON mode, else plain text; the summary line names the mode used.

Options:
  -o, --output FILE  the scene to write (required)
  --emit json|python the scene's JSON (default), or a Python program that builds it with the
                     sdfcsg module (docs/python.md) and saves its JSON, by default beside it
                     (chair.py writes chair.json)
  --render FILE      also render the scene to a PNG (800 x 600)
)";

const char* kEditHelp =
    R"(Usage: sdfcsg edit SCENE "INSTRUCTION" -o OUT.json [--render OUT.png] [options]

Sends SCENE and INSTRUCTION ("make the legs longer") to a language model and writes the
changed scene, validated and repaired as by 'sdfcsg generate'.

Options:
  -o, --output FILE  the scene to write (required; may be SCENE itself)
  --emit json|python the scene's JSON (default), or a Python program that builds it, as for
                     'sdfcsg generate'
  --render FILE      also render the new scene to a PNG (800 x 600)
)";

} // namespace

int runGenerate(int argc, char** argv) {
    Args args = parseArgs(argc, argv, {"-o", "--output", "--render", "--emit"},
                          {"--print-prompt", "--dry-run"});
    if (args.has("--help") || args.has("-h"))
        return std::printf("%s%s", kGenerateHelp, kLlmOptionsHelp), kOk;
    if (!args.error.empty()) return usageError("generate", args.error);
    if (args.positional.size() != 1) return usageError("generate", "expected one \"PROMPT\"");
    GenerateOptions options;
    if (auto error = configure(args, options); !error.empty()) return usageError("generate", error);
    return generateAndWrite("generate", args.positional[0], options, args);
}

int runEdit(int argc, char** argv) {
    Args args = parseArgs(argc, argv, {"-o", "--output", "--render", "--emit"},
                          {"--print-prompt", "--dry-run"});
    if (args.has("--help") || args.has("-h"))
        return std::printf("%s%s", kEditHelp, kLlmOptionsHelp), kOk;
    if (!args.error.empty()) return usageError("edit", args.error);
    if (args.positional.size() != 2)
        return usageError("edit", "expected a SCENE file and an \"INSTRUCTION\"");
    GenerateOptions options;
    if (auto error = configure(args, options); !error.empty()) return usageError("edit", error);
    auto scene = loadScene(args.positional[0]);
    if (!scene) return fail(scene.error());
    options.currentScene = toJson(*scene);
    return generateAndWrite("edit", args.positional[1], options, args);
}

// ---- eval-prompts ----

namespace {

const char* kEvalHelp = R"(Usage: sdfcsg eval-prompts PROMPTS.txt --out DIR [options]

Runs every prompt of PROMPTS.txt (one per line; blank lines and lines starting with # are
skipped) through 'sdfcsg generate' against the configured endpoint. Writes DIR/NN.json and a
256 x 256 render DIR/NN.png per valid scene, a contact sheet of the renders in prompt order
(DIR/contact-sheet.png; each tile numbered in its corner, a red tile for a prompt without a
scene), and a report (DIR/report.txt, also printed): per prompt, whether the first answer was
valid, validity after repair, repair rounds, tokens, seconds and output mode, and the first
problems of a prompt without a scene; then first-try validity, validity after repair, mean
repair rounds, tokens and time over all prompts. A prompt that nearly repeats the request of
one of the system prompt's examples is named in the report, as its first try is no fair test.
Ctrl-C stops after the prompt in progress is abandoned; the report and the contact sheet then
cover the prompts done (exit code 130).

Options:
  --out DIR  output folder (created if missing; required)
)";

// A prompt without a scene shows the error's first line and this many of its problems.
constexpr size_t kProblemsShown = 3;

struct EvalRow {
    std::string prompt;
    GenerateStats stats;
    std::vector<std::string> error; // the error's first lines, if any
    std::optional<Image> image;
};

std::vector<std::string> readPrompts(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back())))
            line.pop_back();
        size_t start = line.find_first_not_of(" \t");
        if (start == std::string::npos || line[start] == '#') continue;
        out.push_back(line.substr(start));
    }
    return out;
}

std::string twoDigits(size_t i) {
    char text[32];
    std::snprintf(text, sizeof text, "%02zu", i);
    return text;
}

// The words of a text that carry its meaning: lower case, three letters or more, without the
// commonest.
std::set<std::string> contentWords(std::string_view text) {
    static const std::set<std::string> kCommon = {"and", "the", "with", "its", "for", "from"};
    std::set<std::string> out;
    std::string word;
    auto flush = [&] {
        if (word.size() >= 3 && !kCommon.count(word)) out.insert(word);
        word.clear();
    };
    for (char c : text) {
        if (std::isalnum(static_cast<unsigned char>(c)))
            word += char(std::tolower(static_cast<unsigned char>(c)));
        else
            flush();
    }
    flush();
    return out;
}

// The example request that `prompt` nearly repeats: one holding at least 80% of its words
// ("A robot with a square body, two legs" in "A robot with a square body, two legs, two arms and
// an antenna."). The model has seen that request answered, so its first try is no fair test.
const std::string* repeatedExample(const std::string& prompt,
                                   const std::vector<std::string>& examples) {
    const std::set<std::string> words = contentWords(prompt);
    if (words.empty()) return nullptr;
    for (const std::string& example : examples) {
        const std::set<std::string> known = contentWords(example);
        size_t shared = 0;
        for (const std::string& w : words)
            shared += known.count(w);
        if (5 * shared >= 4 * words.size()) return &example;
    }
    return nullptr;
}

// Tiles per row of the contact sheet.
uint32_t sheetColumns(size_t tiles) {
    return uint32_t(std::ceil(std::sqrt(double(std::max<size_t>(tiles, 1)))));
}

// Digits 3 x 5, for the tile numbers.
constexpr const char* kDigits[10][5] = {
    {"###", "#.#", "#.#", "#.#", "###"}, {".#.", "##.", ".#.", ".#.", "###"},
    {"###", "..#", "###", "#..", "###"}, {"###", "..#", "###", "..#", "###"},
    {"#.#", "#.#", "###", "..#", "..#"}, {"###", "#..", "###", "..#", "###"},
    {"###", "#..", "###", "#.#", "###"}, {"###", "..#", "..#", "..#", "..#"},
    {"###", "#.#", "###", "#.#", "###"}, {"###", "#.#", "###", "..#", "###"},
};

// `number` in white on a dark label at (x0, y0), each font pixel `scale` pixels wide.
void drawNumber(Image& image, uint32_t x0, uint32_t y0, size_t number, uint32_t scale) {
    const std::string digits = std::to_string(number);
    const uint32_t pad = scale, advance = 4 * scale;
    const uint32_t width = pad + uint32_t(digits.size()) * advance, height = 2 * pad + 5 * scale;
    auto put = [&](uint32_t x, uint32_t y, uint8_t v) {
        if (x >= image.width || y >= image.height) return;
        uint8_t* p = &image.rgba[(size_t(y) * image.width + x) * 4];
        p[0] = p[1] = p[2] = v;
        p[3] = 255;
    };
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x)
            put(x0 + x, y0 + y, 20);
    for (size_t d = 0; d < digits.size(); ++d)
        for (uint32_t row = 0; row < 5; ++row)
            for (uint32_t col = 0; col < 3; ++col)
                if (kDigits[digits[d] - '0'][row][col] == '#')
                    for (uint32_t y = 0; y < scale; ++y)
                        for (uint32_t x = 0; x < scale; ++x)
                            put(x0 + pad + uint32_t(d) * advance + col * scale + x,
                                y0 + pad + row * scale + y, 255);
}

Image contactSheet(const std::vector<EvalRow>& rows, uint32_t tile) {
    constexpr uint32_t kGap = 4;
    const uint32_t n = uint32_t(std::max<size_t>(rows.size(), 1));
    const uint32_t columns = sheetColumns(n);
    const uint32_t lines = (n + columns - 1) / columns;
    Image sheet;
    sheet.width = columns * tile + (columns + 1) * kGap;
    sheet.height = lines * tile + (lines + 1) * kGap;
    sheet.rgba.assign(size_t(sheet.width) * sheet.height * 4, 40);
    for (size_t i = 0; i < size_t(sheet.width) * sheet.height; ++i)
        sheet.rgba[i * 4 + 3] = 255;
    for (size_t i = 0; i < rows.size(); ++i) {
        const uint32_t x0 = kGap + uint32_t(i % columns) * (tile + kGap);
        const uint32_t y0 = kGap + uint32_t(i / columns) * (tile + kGap);
        for (uint32_t y = 0; y < tile; ++y)
            for (uint32_t x = 0; x < tile; ++x) {
                uint8_t* dst = &sheet.rgba[(size_t(y0 + y) * sheet.width + x0 + x) * 4];
                const Image* img = rows[i].image ? &*rows[i].image : nullptr;
                if (img && x < img->width && y < img->height) {
                    std::copy_n(&img->rgba[(size_t(y) * img->width + x) * 4], 4, dst);
                } else {
                    const uint8_t failed[4] = {150, 40, 40, 255};
                    std::copy_n(failed, 4, dst);
                }
            }
        drawNumber(sheet, x0 + 4, y0 + 4, i + 1, std::max(2u, tile / 64));
    }
    return sheet;
}

// `total` is the number of prompts in the file; fewer rows mean the run was interrupted.
std::string evalReport(const std::vector<EvalRow>& rows, size_t total) {
    std::string out;
    char line[512];
    if (rows.size() < total)
        out += "interrupted after " + counted(rows.size(), "prompt") + " of " +
               std::to_string(total) + "; what follows covers those\n";
    const std::vector<std::string> examples = sceneExampleRequests();
    for (size_t i = 0; i < rows.size(); ++i)
        if (const std::string* example = repeatedExample(rows[i].prompt, examples))
            out += "note: prompt " + std::to_string(i + 1) +
                   " nearly repeats the request of an example in the system prompt (\"" + *example +
                   "\"), so its first-try validity is inflated\n";
    if (!out.empty()) out += "\n";
    std::snprintf(line, sizeof line, "%-3s %-50s %-6s %-6s %-8s %-16s %-8s %s\n", "#", "prompt",
                  "first", "valid", "repairs", "tokens in+out", "seconds", "mode");
    out += line;
    int firstTry = 0, valid = 0, answered = 0, repairs = 0;
    uint64_t in = 0, outTokens = 0;
    double seconds = 0;
    for (size_t i = 0; i < rows.size(); ++i) {
        const GenerateStats& s = rows[i].stats;
        std::string prompt =
            rows[i].prompt.size() > 50 ? rows[i].prompt.substr(0, 47) + "..." : rows[i].prompt;
        std::string tokens =
            std::to_string(s.promptTokens) + "+" + std::to_string(s.completionTokens);
        std::snprintf(line, sizeof line, "%-3zu %-50s %-6s %-6s %-8d %-16s %-8.1f %.*s\n", i + 1,
                      prompt.c_str(), s.firstTryValid ? "yes" : "no", s.valid ? "yes" : "no",
                      std::max(0, s.answers - 1), tokens.c_str(), s.seconds,
                      int(outputModeName(s.mode).size()), outputModeName(s.mode).data());
        out += line;
        for (size_t k = 0; k < rows[i].error.size(); ++k)
            out += (k == 0 ? "    error: " : "           ") + rows[i].error[k] + "\n";
        firstTry += s.firstTryValid;
        valid += s.valid;
        if (s.answers > 0) {
            ++answered;
            repairs += s.answers - 1;
        }
        in += s.promptTokens;
        outTokens += s.completionTokens;
        seconds += s.seconds;
    }
    const double n = std::max<double>(double(rows.size()), 1.0);
    std::snprintf(line, sizeof line,
                  "\nprompts: %zu\nfirst-try validity: %d of %zu (%.0f%%)\n"
                  "validity after repair: %d of %zu (%.0f%%)\n"
                  "mean repair rounds: %.2f (over %s with an answer)\n"
                  "tokens: %llu prompt + %llu completion\ntime: %.1f s in all, %.1f s per prompt\n",
                  rows.size(), firstTry, rows.size(), 100.0 * firstTry / n, valid, rows.size(),
                  100.0 * valid / n, answered ? double(repairs) / answered : 0.0,
                  counted(size_t(answered), "prompt").c_str(), static_cast<unsigned long long>(in),
                  static_cast<unsigned long long>(outTokens), seconds, seconds / n);
    out += line;
    const uint32_t columns = sheetColumns(rows.size());
    return out + "contact sheet: the prompts' renders in order, " + counted(columns, "tile") +
           " a row, each numbered in its top-left corner" +
           (columns > 1 ? " (prompt " + std::to_string(columns + 1) + " starts the second row)"
                        : std::string()) +
           "; red: no scene\n";
}

// The error's first line and the first few of its problems, for the report.
std::vector<std::string> errorLines(const Error& error) {
    std::vector<std::string> out;
    const auto& all = error.diagnostics;
    for (size_t k = 0; k < all.size() && k <= kProblemsShown; ++k)
        out.push_back(all[k].str());
    if (all.size() > kProblemsShown + 1)
        out.push_back("(" + counted(all.size() - kProblemsShown - 1, "more problem") + ")");
    return out;
}

} // namespace

int runEvalPrompts(int argc, char** argv) {
    Args args = parseArgs(argc, argv, {"--out"}, {});
    if (args.has("--help") || args.has("-h"))
        return std::printf("%s%s", kEvalHelp, kLlmOptionsHelp), kOk;
    if (!args.error.empty()) return usageError("eval-prompts", args.error);
    if (args.positional.size() != 1) return usageError("eval-prompts", "expected one PROMPTS file");
    const std::string dir = args.get("--out");
    if (dir.empty()) return usageError("eval-prompts", "missing --out DIR");
    GenerateOptions options;
    if (auto error = configure(args, options); !error.empty())
        return usageError("eval-prompts", error);
    auto text = readFile(args.positional[0]);
    if (!text) return fail(text.error());
    const std::vector<std::string> prompts = readPrompts(*text);
    if (prompts.empty()) return usageError("eval-prompts", "no prompts in " + args.positional[0]);
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec)
        return fail(Error::message(ErrorKind::Io, dir, "cannot create folder: " + ec.message()));

    Recording recording;
    if (auto ready = recording.setUp(args, options); !ready) return fail(ready.error());
    ProgressPrinter printer;
    options.progress = [&printer](const GenerateProgress& p) { printer(p); };
    catchInterrupts();
    options.cancelled = [] { return interrupted(); };
    Renders renders;
    std::vector<EvalRow> rows;
    for (size_t i = 0; i < prompts.size() && !interrupted(); ++i) {
        std::fprintf(stderr, "[%zu/%zu] %s\n", i + 1, prompts.size(), prompts[i].c_str());
        EvalRow row{prompts[i], {}, {}, std::nullopt};
        auto generated = generateScene(prompts[i], options, &row.stats);
        printer.clear();
        if (interrupted()) break; // the prompt in progress was abandoned: it has no result
        if (!generated) {
            if (generated.error().kind == ErrorKind::Usage) return fail(generated.error());
            row.error = errorLines(generated.error());
            std::fprintf(stderr, "%s\n", generated.error().str().c_str());
        } else {
            const std::string base = (fs::path(dir) / twoDigits(i + 1)).string();
            if (auto w =
                    writeWhole([&] { return writeFileAtomic(base + ".json", generated->json); });
                !w)
                return fail(w.error());
            for (const Diagnostic& w : generated->warnings)
                std::fprintf(stderr, "warning: %s: %s\n", w.path.c_str(), w.message.c_str());
            auto image = renders.render(generated->scene, 256, 256);
            if (!image && interrupted()) {
                row.error = {"render: interrupted"}; // its scene was written
                rows.push_back(std::move(row));
                break;
            }
            if (!image) {
                row.error = {"render: " + image.error().diagnostics.front().message};
            } else {
                if (auto w = writeWhole([&] { return writePng(*image, base + ".png"); }); !w)
                    return fail(w.error());
                row.image = std::move(*image);
            }
        }
        rows.push_back(std::move(row));
    }
    Finishing finishing; // an interrupted run still leaves its recording and report
    if (auto saved = recording.save(); !saved) return fail(saved.error());
    const std::string report = evalReport(rows, prompts.size());
    std::fputs(report.c_str(), stdout);
    if (auto w = writeFileAtomic((fs::path(dir) / "report.txt").string(), report); !w)
        return fail(w.error());
    if (auto w = writePng(contactSheet(rows, 256), fs::path(dir) / "contact-sheet.png"); !w)
        return fail(w.error());
    if (interrupted())
        return stopInterrupted("sdfcsg: interrupted after " + counted(rows.size(), "prompt") +
                               " of " + std::to_string(prompts.size()) +
                               "; the report covers those");
    return kOk;
}

} // namespace sdfcsg::app
