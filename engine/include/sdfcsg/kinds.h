// sdfcsg: the node kinds, in the order that numbers them, grouped by role.
//
// This list is the one place where a kind gets its number. nodes.h makes NodeKind from it; the
// build makes the same numbers for the shaders (kKindSphere ... in kinds.glsl, written by
// engine/tools/kinds_glsl.cpp), and engine/src/field/sdf.h checks the two against each other.
// A kind's table entry (engine/src/scene/nodes.cpp) says everything else about it; adding a kind
// is a line here, that entry and its formula (docs/vocabulary.md).
//
// The groups stay in this order: primitives, 2D profiles, then the operations (nodes with
// children): Boolean, value and domain operations. Within a group the order is free.
#pragma once

#define SDFCSG_PRIMITIVE_KINDS(X)                                                                  \
    X(Sphere)                                                                                      \
    X(Box)                                                                                         \
    X(RoundBox)                                                                                    \
    X(Plane)                                                                                       \
    X(TriangularPrism)                                                                             \
    X(Torus)                                                                                       \
    X(Cylinder)                                                                                    \
    X(Cone)                                                                                        \
    X(Capsule)                                                                                     \
    X(Ellipsoid)                                                                                   \
    X(HexPrism)                                                                                    \
    X(Octahedron)                                                                                  \
    X(Pyramid)                                                                                     \
    X(RoundedCylinder)                                                                             \
    X(RoundCone)                                                                                   \
    X(Link)                                                                                        \
    X(Heightmap)                                                                                   \
    X(Mesh)                                                                                        \
    X(CappedTorus)

// Shapes in the xy plane, for extrude and revolve.
#define SDFCSG_PROFILE_KINDS(X)                                                                    \
    X(Circle)                                                                                      \
    X(Rectangle)                                                                                   \
    X(RegularPolygon)                                                                              \
    X(Polygon)                                                                                     \
    X(Text)                                                                                        \
    X(Image)

// Operations of any number of children; the transitions take exactly two and come last.
#define SDFCSG_BOOLEAN_KINDS(X)                                                                    \
    X(Union)                                                                                       \
    X(Intersection)                                                                                \
    X(Difference)                                                                                  \
    X(TransitionLinear)                                                                            \
    X(TransitionRadial)

// Operations that change their one child's value.
#define SDFCSG_VALUE_KINDS(X)                                                                      \
    X(Shell)                                                                                       \
    X(Offset)

// Operations that change the space their one child is evaluated in.
#define SDFCSG_DOMAIN_KINDS(X)                                                                     \
    X(Repeat)                                                                                      \
    X(PolarRepeat)                                                                                 \
    X(Mirror)                                                                                      \
    X(Elongate)                                                                                    \
    X(Twist)                                                                                       \
    X(Bend)                                                                                        \
    X(Taper)                                                                                       \
    X(BendLinear)                                                                                  \
    X(Extrude)                                                                                     \
    X(Revolve)

#define SDFCSG_NODE_KINDS(X)                                                                       \
    SDFCSG_PRIMITIVE_KINDS(X)                                                                      \
    SDFCSG_PROFILE_KINDS(X)                                                                        \
    SDFCSG_BOOLEAN_KINDS(X) SDFCSG_VALUE_KINDS(X) SDFCSG_DOMAIN_KINDS(X)
