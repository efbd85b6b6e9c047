// Stage 2: the normal of the height field, computed once per shadel by central differences of
// the height function one shadel apart (the footprint's world size), and bent from the mesh's
// normal in the surface's tangent frame. Kept in the radiance layer until the shade stage.
void main() {
    float step = max(length(surface.positionDx), 1e-3);
    vec2 p = surface.position.xz;
    float dx = terrainHeight(p + vec2(step, 0.0)) - terrainHeight(p - vec2(step, 0.0));
    float dz = terrainHeight(p + vec2(0.0, step)) - terrainHeight(p - vec2(0.0, step));
    vec3 slope = normalize(vec3(-dx, 2.0 * step, -dz)); // in the world's x, up, z
    vec3 n = surface.normal;
    vec3 t = normalize(abs(n.y) < 0.99 ? cross(vec3(0.0, 0.0, 1.0), n) : vec3(1.0, 0.0, 0.0));
    vec3 b = cross(t, n);
    writeLayer(LAYER_RADIANCE, vec4(normalize(t * slope.x + n * slope.y + b * slope.z), 0.0));
}
