#include "sdfcsg/error.h"

namespace sdfcsg {

std::string Diagnostic::str() const {
    std::string out = file.empty() ? std::string("<input>") : file;
    if (line > 0) out += ":" + std::to_string(line) + ":" + std::to_string(column);
    out += ": ";
    if (!path.empty()) out += path + ": ";
    out += message;
    return out;
}

std::string Error::str() const {
    std::string out;
    for (const Diagnostic& d : diagnostics) {
        if (!out.empty()) out += '\n';
        out += d.str();
    }
    return out;
}

} // namespace sdfcsg
