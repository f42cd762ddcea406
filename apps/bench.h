// sdfcsg bench: frame times and JSON-to-pipeline times on the bundled scenes; with --mesh, mesh
// extraction times per stage at several resolutions; with --mesh-node, the time from a mesh file
// to a mesh node's ready field.
#pragma once

namespace sdfcsg::app {

// `sdfcsg bench [--scenes DIR] [--width W] [--height H] [--frames N]` or
// `sdfcsg bench --mesh [--scenes DIR] [--resolutions 128,256,512] [--runs N]`; argv holds the
// arguments after "bench". Prints a table to stdout; returns a process exit code.
int runBench(int argc, char** argv);

// `sdfcsg bench --mesh-node FILE... [--resolution N] [--runs N]` (bench_mesh_node.cpp).
int runMeshNodeBench(int argc, char** argv);

} // namespace sdfcsg::app
