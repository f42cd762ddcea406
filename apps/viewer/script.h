// Command files that drive the viewer without a person: one command per line, '#' starts a
// comment. Each command acts on the viewer as the matching control would:
//
//   select NODE              a node by name or index ("none" clears the selection)
//   set KEY V...             a value of the selected node (radius 0.5, translate 0 1 0, ...)
//   mode shaded|normals|depth|steps
//   shadows on|off    ao on|off    grid on|off    boxes none|all|selected
//   orbit DYAW DPITCH        turn the camera, in degrees
//   drag DYAW DPITCH         the same as a mouse drag: the view counts as moving for a moment,
//                            so previews are drawn until it settles
//   zoom FACTOR              multiply the distance to the target
//   frame    reset           frame the selection (or scene), or go back to the scene's camera
//   undo    redo
//   add KIND                 a child of the selected operation, which selects it
//   remove                   the selected node and its subtree
//   kind KIND                turn the selected primitive (operation) into another one
//   op union|intersection|difference|...   the same, for operations only
//   move up|down             the selected node among its siblings
//   parent NODE [INDEX]      move the selected node and its subtree under the operation NODE,
//                            as child INDEX (0 first; the first child of a difference is what
//                            the others are cut from) or last; it stays selected
//   open PATH                load a scene file as the file panel does (a failure is no
//                            script error: the scene stays, see expect-error)
//   save [PATH]              write the scene as JSON (no PATH: where Ctrl+S writes)
//   wait-reload              wait until the scene's file changed on disk and was reloaded
//                            (each reload answers one wait, also one that came first)
//   pick X Y                 wait for the full-resolution image, then click window pixel X, Y
//   ui on|off                show or hide the panels (H)
//   screenshot PATH          wait for the full-resolution image, then write the window as PNG
//                            (in the mesh view the printed line gives the mesh's drawing time)
//   print-bounds NODE        wait for the full-resolution image, then print the window pixels
//                            NODE's bounds cover: "bounds NODE X0 Y0 X1 Y1" (end exclusive)
//   expect-error TEXT...     fail unless the shown error holds TEXT ("none": unless none shows)
//   expect-selected NODE     fail unless NODE (a name, an index or "none") is selected
//   generate TEXT...         ask the language model for a new scene described by TEXT, wait
//                            for it, and make it the current scene (one undo step)
//   edit-scene TEXT...       the same, sending the current scene to be changed as TEXT says
//   mesh extract CELLS       extract a mesh with CELLS along the longest axis, wait for it and
//                            show it (the mesh panel's resolution)
//   mesh export PATH         write the mesh (.ply, .obj, .stl, .glb) and wait for the file
//   view mesh|march          the extracted mesh or the ray-marched image
//   wireframe on|off         the mesh view's edges
//   thin-walls on|off        the mesh's vertices over walls thinner than 0.8 mm (one scene unit
//                            a centimetre) drawn red
//
// Numbers must be finite. The text of generate, edit-scene and expect-error is the rest of the
// line, so it cannot hold a '#'. A generation, extraction or export that fails (no valid
// scene after the repair rounds, a network error, a mesh too large for the memory) fails
// the script.
#pragma once

#include <sdfcsg/error.h>

#include <string>
#include <string_view>
#include <vector>

namespace sdfcsg::viewer {

struct Command {
    int line = 0;
    std::string verb;
    std::vector<std::string> args;
    std::vector<float> numbers; // args read as numbers, for commands that take numbers
    std::string text;           // the rest of the line after the verb, trimmed, for free text
};

// Parses and checks every line (known verb, argument count and values); all problems are
// reported, each as "file:line:column: message".
Result<std::vector<Command>> parseScript(std::string_view text, std::string_view file);

} // namespace sdfcsg::viewer
