// What the viewer's mesh-view shaders share: the push constants, set by drawMesh() in
// mesh_view.cpp (MeshConstants there has the same layout).

layout(push_constant) uniform MeshConstants {
    vec4 eye;     // xyz: the camera; w: distance of the near plane
    vec4 right;   // xyz: the camera's right / (tan(fov / 2) * aspect); w: a pixel's width at
                  // unit distance
    vec4 up;      // xyz: the camera's up / tan(fov / 2); w: ground grid lines on each side
    vec4 forward; // xyz: the view direction; w: 1 when drawing the wireframe
    vec4 line;    // rgb: colour of the edges; a: their width in pixels
    vec4 grid;    // ground grid: xy: centre (x, z); z: height of its plane; w: line spacing
} pc;

// The ray marcher's camera (engine/src/render/camera.h), so the mesh lies on the ray-marched surface
// pixel for pixel. Vulkan's y points down the image as the ray marcher's pixel rows do, hence
// -up. Depth is reversed (near / distance: 1 at the near plane, towards 0 far away), which keeps
// float depth precise at every distance and needs no far plane.
vec4 project(vec3 d) {
    return vec4(dot(d, pc.right.xyz), -dot(d, pc.up.xyz), pc.eye.w, dot(d, pc.forward.xyz));
}
