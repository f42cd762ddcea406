// Stand-in for the generated scene, used only to syntax-check the kernels at build time.
float sceneDistance(vec3 p) {
    return sdSphere(toLocal(0u, p), nodes[0].p0.x) * nodes[0].color.w;
}

vec4 sceneSample(vec3 p) {
    return vec4(nodes[0].color.rgb, sceneDistance(p));
}
