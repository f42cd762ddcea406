// A small streaming JSON writer with one fixed layout: 2-space indentation, and objects and
// arrays either one member per line or inline ("[1, 2, 3]", {"$ref": "x"}) as the caller asks.
// Used for scene files and the generated JSON Schema so both read the same way.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace sdfcsg::detail {

// Shortest text that reads back as exactly `value` (std::to_chars).
std::string formatNumber(double value);
// Shortest text that reads back as exactly `value` when parsed as a double and narrowed to
// float, which is what the scene parser does.
std::string formatFloat(float value);
// `text` as a JSON string literal, quotes included.
std::string jsonQuote(std::string_view text);

class JsonWriter {
  public:
    enum class Layout { Block, Inline };

    void beginObject(Layout layout = Layout::Block);
    void endObject();
    void beginArray(Layout layout = Layout::Block);
    void endArray();
    void key(std::string_view name);
    void string(std::string_view text);
    void number(double value);
    void number(float value);
    void boolean(bool value);
    void null();
    // The finished document, with a final newline.
    std::string finish();

  private:
    struct Level {
        bool inlined;
        bool empty = true;
    };
    void beforeValue();
    void newline(size_t depth);

    std::string out_;
    std::vector<Level> levels_;
    bool afterKey_ = false;
};

} // namespace sdfcsg::detail
