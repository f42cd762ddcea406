// Writes kinds.glsl: NodeKind's numbers as GLSL constants (kKindSphere, ...), and the first kind
// of each group, from sdfcsg/kinds.h through the same preprocessor that numbers the enum. The
// build runs it before it embeds and checks the shaders; engine/src/field/sdf.h compiles the
// output as C++ and checks every constant against NodeKind.
//
// Usage: kinds_glsl OUTPUT (rewritten only when its text changes).
#include "sdfcsg/kinds.h"

#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <string>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: kinds_glsl OUTPUT\n";
        return 2;
    }
    std::ostringstream out;
    out << "// Generated from engine/include/sdfcsg/kinds.h by engine/tools/kinds_glsl.cpp. Do not "
           "edit.\n// NodeKind's numbers.\n";
    unsigned n = 0;
    auto line = [&](const char* name) {
        out << "const uint kKind" << name << " = " << n++ << "u;\n";
    };
    auto first = [&](const char* group) {
        out << "const uint kKindFirst" << group << " = " << n << "u;\n";
    };
#define SDFCSG_KIND_LINE(name) line(#name);
    SDFCSG_PRIMITIVE_KINDS(SDFCSG_KIND_LINE)
    first("Profile");
    SDFCSG_PROFILE_KINDS(SDFCSG_KIND_LINE)
    first("Operation");
    SDFCSG_BOOLEAN_KINDS(SDFCSG_KIND_LINE)
    first("ValueOperation");
    SDFCSG_VALUE_KINDS(SDFCSG_KIND_LINE)
    first("DomainOperation");
    SDFCSG_DOMAIN_KINDS(SDFCSG_KIND_LINE)
#undef SDFCSG_KIND_LINE
    out << "const uint kKindCount = " << n << "u;\n";
    // The tape machine's operation bits (SDFCSG_TAPE_OPERATIONS, shaders/tape.glsl): bit k for
    // kind kKindFirstOperation + k, as preprocessor numbers for its #if.
    unsigned bit = 0, booleans = 0, values = 0;
#define SDFCSG_KIND_BIT(name) booleans |= 1u << bit++;
    SDFCSG_BOOLEAN_KINDS(SDFCSG_KIND_BIT)
#undef SDFCSG_KIND_BIT
#define SDFCSG_KIND_BIT(name) values |= 1u << bit++;
    SDFCSG_VALUE_KINDS(SDFCSG_KIND_BIT)
#undef SDFCSG_KIND_BIT
    // The transitions, the Boolean kinds after union, intersection and difference.
    const unsigned transitions = booleans & ~7u;
    out << "#define SDFCSG_BOOLEAN_OPERATION_BITS " << booleans
        << "\n#define SDFCSG_VALUE_OPERATION_BITS " << values
        << "\n#define SDFCSG_TRANSITION_OPERATION_BITS " << transitions << "\n";

    const std::string text = out.str();
    std::ifstream old(argv[1], std::ios::binary);
    if (old && std::string(std::istreambuf_iterator<char>(old), {}) == text) return 0;
    std::ofstream file(argv[1], std::ios::binary | std::ios::trunc);
    file << text;
    return file.good() ? 0 : 1;
}
