// The terrain's height field over the surface's (u, v) plane, in metres: a few octaves of
// smooth value noise. Every stage of the terrain program sees this file before its own.
float terrainHash(vec2 cell) {
    return fract(sin(dot(cell, vec2(127.1, 311.7))) * 43758.5453);
}

float terrainNoise(vec2 x) {
    vec2 i = floor(x), f = fract(x);
    vec2 w = f * f * (3.0 - 2.0 * f);
    float a = terrainHash(i), b = terrainHash(i + vec2(1.0, 0.0));
    float c = terrainHash(i + vec2(0.0, 1.0)), d = terrainHash(i + vec2(1.0, 1.0));
    return mix(mix(a, b, w.x), mix(c, d, w.x), w.y);
}

float terrainHeight(vec2 p) {
    float h = 0.0, amplitude = 1.0;
    for (int octave = 0; octave < 4; ++octave) {
        h += amplitude * terrainNoise(p * frequency);
        p *= 2.03;
        amplitude *= 0.45;
    }
    return h * heightScale;
}
