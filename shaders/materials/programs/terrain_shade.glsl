// Stage 3: the scene's lighting of the terrain's material with the stage 2 normal.
void main() {
    vec4 m = readLayer(LAYER_MATERIAL);
    vec3 n = readLayer(LAYER_RADIANCE).xyz;
    writeLayer(LAYER_RADIANCE, vec4(lightSurface(m.rgb, 0.0, m.a, n), 1.0));
}
