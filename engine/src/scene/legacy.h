// The original SDFBooleanEngine format: a flat array of binary nodes, the last one the root.
#pragma once

#include "scene/parse_util.h"

namespace sdfcsg::detail {

// True for a top-level object with a "nodes" array and no "version".
bool isLegacyScene(element top);

// Converts a legacy scene into the current model, reporting problems with "nodes[i]" paths.
// Node paths of the result are "nodes[i]" too.
Scene convertLegacy(simdjson::dom::object top, const Limits& limits, Problems& problems);

} // namespace sdfcsg::detail
