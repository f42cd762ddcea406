// sdfcsg bench: frame times and JSON-to-pipeline times on the bundled scenes.
#pragma once

namespace sdfcsg::app {

// `sdfcsg bench [--scenes DIR] [--width W] [--height H] [--frames N]`; argv holds the arguments
// after "bench". Prints a table to stdout; returns a process exit code.
int runBench(int argc, char** argv);

} // namespace sdfcsg::app
