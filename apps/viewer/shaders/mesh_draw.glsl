// What the mesh pipeline's two stages share: the push constants, set by drawMesh() in
// presenter.cpp (MeshConstants there has the same layout).

layout(push_constant) uniform MeshConstants {
    vec4 eye;     // xyz: the camera; w: distance of the near plane
    vec4 right;   // xyz: the camera's right / (tan(fov / 2) * aspect)
    vec4 up;      // xyz: the camera's up / tan(fov / 2)
    vec4 forward; // xyz: the view direction; w: 1 when drawing the wireframe
    vec4 line;    // rgb: colour of the edges; a: their width in pixels
} pc;
