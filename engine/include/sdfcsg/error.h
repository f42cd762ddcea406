// sdfcsg: errors the user can cause come back as values.
//
// A Diagnostic names the file, the JSON path of the offending value and what was expected.
// Vulkan failures that can only be bugs abort with file:line instead (VK_CHECK in
// engine/vulkan/vulkan_helpers.h).
#pragma once

#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace sdfcsg {

struct Diagnostic {
    std::string file;    // source file as given by the caller, "<input>" for strings
    std::string path;    // JSON path such as "root.children[2].radius"; empty for file-level errors
    std::string message; // what was expected and what was found
    int line = 0;        // 1-based line and column, set for JSON syntax errors only
    int column = 0;

    // "file:line:column: message" for syntax errors, "file: path: message" otherwise.
    std::string str() const;
};

// Remote: an HTTP service (a language model endpoint) failed, refused or answered unusably.
// Cancelled: a callback asked long work (a render, a mesh extraction, a generation) to stop.
enum class ErrorKind { Io, Syntax, Validation, Limit, Shader, Vulkan, Usage, Remote, Cancelled };

struct Error {
    ErrorKind kind = ErrorKind::Validation;
    std::vector<Diagnostic> diagnostics; // at least one

    Error() = default;
    Error(ErrorKind k, Diagnostic d) : kind(k), diagnostics{std::move(d)} {}
    Error(ErrorKind k, std::vector<Diagnostic> ds) : kind(k), diagnostics(std::move(ds)) {}
    static Error message(ErrorKind k, std::string file, std::string text) {
        return Error(k, Diagnostic{std::move(file), {}, std::move(text)});
    }

    // All diagnostics, one per line, without a trailing newline.
    std::string str() const;
};

// Either a value or an Error. Test with `if (!r)`, then use `*r` / `r->` or `r.error()`.
template <class T> class [[nodiscard]] Result {
  public:
    Result(T value) : v_(std::in_place_index<0>, std::move(value)) {}
    Result(Error error) : v_(std::in_place_index<1>, std::move(error)) {}

    explicit operator bool() const { return v_.index() == 0; }
    T& operator*() { return std::get<0>(v_); }
    const T& operator*() const { return std::get<0>(v_); }
    T* operator->() { return &std::get<0>(v_); }
    const T* operator->() const { return &std::get<0>(v_); }
    const Error& error() const { return std::get<1>(v_); }

  private:
    std::variant<T, Error> v_;
};

struct Ok {};
using Status = Result<Ok>;

} // namespace sdfcsg
