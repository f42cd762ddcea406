// sdfcsg generate, edit and eval-prompts: scenes from plain language through a language model
// (the engine's generate.h), with the scene written, and rendered on request.
#pragma once

namespace sdfcsg::app {

// Each takes the arguments after its command name and returns a process exit code.
int runGenerate(int argc, char** argv);    // sdfcsg generate "PROMPT" -o scene.json [...]
int runEdit(int argc, char** argv);        // sdfcsg edit scene.json "INSTRUCTION" -o new.json
int runEvalPrompts(int argc, char** argv); // sdfcsg eval-prompts PROMPTS.txt --out DIR

} // namespace sdfcsg::app
