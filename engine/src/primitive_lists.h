// Primitive lists: the operands of a sharp union that are primitives of one kind, evaluated by
// the generated code in a loop over a list chosen per region of space, so that a region pays
// only for the primitives that can be nearest in it (pruning as in Lipschitz Pruning,
// Eurographics 2025, at the granularity of a list per region).
//
// In a region R, operand i of union u can be left out when a lower bound of its value over R
// exceeds an upper bound of the union's value over R: the union's value is then exact in R.
#pragma once

#include "sdfcsg/eval.h"
#include "sdfcsg/scene.h"

#include <cstdint>
#include <vector>

namespace sdfcsg::detail {

struct PrimitiveList {
    uint32_t unionNode;
    NodeKind kind;
    std::vector<uint32_t> members; // operands of unionNode, in order
};

// Unions with no smoothing; per union, one list per primitive kind that has at least
// kMinListLength operands there. List g is called g in the generated code.
inline constexpr size_t kMinListLength = 4;
std::vector<PrimitiveList> primitiveLists(const Scene& scene, const Evaluator& evaluator);

// The members of each list that can change the field inside `region` (a box of half-diagonal
// `radius` around `centre`), appended to `items`; `ranges` gets one [begin, end) per list.
void pruneLists(const std::vector<PrimitiveList>& lists, const Evaluator& evaluator,
                const Aabb& region, std::vector<uint32_t>& items,
                std::vector<uint32_t>& ranges);

} // namespace sdfcsg::detail
