// Helpers shared by the scene parser (parse.cpp) and the legacy importer (legacy.cpp): a capped
// list of problems, descriptions of JSON values for messages, did-you-mean, and typed readers
// that report what was expected and what was found.
#pragma once

#include "sdfcsg/scene.h"

#include "scene/json_writer.h"

#include <simdjson.h>

#include <glm/vec3.hpp>

#include <functional>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace sdfcsg::detail {

using simdjson::dom::element;

// The array or object behind an element whose type was checked. By value: ranging over
// get_array().value_unsafe() directly would refer into a destroyed temporary.
inline simdjson::dom::array asArray(element e) {
    return e.get_array().value_unsafe();
}
inline simdjson::dom::object asObject(element e) {
    return e.get_object().value_unsafe();
}

// Enough to fix a file in a few rounds without flooding a terminal.
inline constexpr size_t kMaxProblems = 50;
// The longest scene or node name.
inline constexpr size_t kMaxNameCharacters = 200;

class Problems {
  public:
    explicit Problems(std::string file) : file_(std::move(file)) {}

    // Once full, further problems are counted but not kept; callers may skip costly checks.
    bool full() const { return diagnostics_.size() >= kMaxProblems; }
    bool empty() const { return diagnostics_.empty(); }
    // Every problem added so far, kept or not.
    size_t count() const { return diagnostics_.size() + dropped_; }
    void add(std::string path, std::string message, ErrorKind kind = ErrorKind::Validation);
    // While set, what it returns is added to every message: where in the copies that uses make
    // the problem lies (" (in the use of \"leg\" at root.children[0])"), or "".
    void setContext(std::function<std::string()> context) { context_ = std::move(context); }
    // The collected problems; the error's kind is that of the first one.
    Error error() const;
    const std::string& file() const { return file_; }

  private:
    std::string file_;
    std::vector<Diagnostic> diagnostics_;
    ErrorKind kind_ = ErrorKind::Validation;
    size_t dropped_ = 0;
    std::function<std::string()> context_;
};

// A JSON value as it appears in "got ...": -1, "abc", true, [1, 2], an object, ...
std::string describe(element value);
// A string as it appears in messages: quoted, escaped as printable() escapes it (and quotes
// and backslashes as in JSON), and cut short when long.
std::string quote(std::string_view text);
// Text from outside (a server's error message, a model's answer) as it may go into a message
// for a terminal: control characters (C0, DEL, C1) become \u001b and the like (\n for a
// newline), and bytes that are not UTF-8 become \xNN, so that the text cannot move the cursor,
// recolour the terminal or forge a line of output. Backslashes are kept, so a second pass
// changes nothing.
std::string printable(std::string_view text);
// "a.b" / "a[3]" path building.
std::string member(std::string_view path, std::string_view key);
std::string item(std::string_view path, size_t index);
// `; did you mean "x"?` for the closest candidate, or "" when none is close.
std::string didYouMean(std::string_view word, std::span<const std::string_view> candidates);
// "a, b and c" (or "a, b or c")
std::string joinNames(std::span<const std::string_view> names, std::string_view last = "and");

// What a value of this type and check must be, e.g. "a positive number".
std::string expectedText(ValueType type, Check check);
// What a node parameter takes: its type and check, its maximum, its choices.
std::string expectedText(const ParamInfo& p);

// Typed readers. On failure they report one problem (with path) and return nothing.
std::optional<double> readNumber(element value, const std::string& path, Check check,
                                 Problems& problems);
std::optional<glm::vec3> readVec3(element value, const std::string& path, Check check,
                                  Problems& problems);
// [r, g, b] with components in 0..1, or "#rrggbb".
std::optional<glm::vec3> readColor(element value, const std::string& path, Problems& problems);
std::optional<std::string> readString(element value, const std::string& path, size_t maxChars,
                                      Problems& problems);

// Object members by key, with unknown keys and duplicates reported. The result holds, per key
// of `keys`, the member's value or nothing. Only the first `listed` keys are suggested and
// listed in messages; the rest are accepted for the caller to judge. `owner` ("for a sphere")
// goes into the message for an unknown key that has no close match.
std::vector<std::optional<element>> readMembers(simdjson::dom::object object,
                                                const std::string& path,
                                                std::span<const std::string_view> keys,
                                                size_t listed, std::string_view owner,
                                                Problems& problems);

// Writes a JSON value through the writer, iteratively (a definition's node may be deep): objects
// one member a line and arrays on one line unless they hold objects, or everything on one line
// when `inlined`. Numbers as formatNumber() writes them, so that a value written, read and
// written again reads the same.
void writeJson(JsonWriter& w, element value, bool inlined);
// The same on one line, as a string: the JSON text of a value.
std::string jsonText(element value);

} // namespace sdfcsg::detail
