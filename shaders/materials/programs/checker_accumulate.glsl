// A procedural that aliases when point-sampled (the one-texel checker of the object's material,
// common/material.glsl texelChecker) made smooth over frames instead of within one: each frame
// lights one sample of the shadel's footprint and folds it into the running mean of the samples
// before, which a preserved layer keeps (prevSample: last frame's value of this same
// shadel, or none). On a still view the mean converges to the footprint's box
// average of displayed colours (as the supersampled reference averages pixels: toDisplay); the
// sample count lives in the material layer's alpha (0..255).
void main() {
    vec4 mean, history;
    float n = 1.0;
    if (prevSample(LAYER_RADIANCE, mean) && prevSample(LAYER_MATERIAL, history))
        n = min(round(history.a * 255.0) + 1.0, maxSamples);
    // The n-th point of the R2 low-discrepancy sequence, shifted by a random offset per shadel:
    // the footprint fills evenly whatever the count (an error near 1/n, not 1/sqrt(n)).
    vec2 offset = vec2(shadelRandomFixed(0u), shadelRandomFixed(1u));
    vec2 jitter = fract(offset + n * vec2(0.7548776662, 0.5698402910)) - 0.5;
    vec2 uv = surface.uv + jitter.x * surface.uvDx + jitter.y * surface.uvDy;
    float checker = mix(0.08, 1.0, texelChecker(uv, material.proceduralScale));
    vec3 base = material.baseColorFactor.rgb * checker;
    vec3 color = lightSurface(base, material.metallicFactor, material.roughnessFactor,
                              surface.normal);
    if (n > 1.0) color = fromDisplay(mix(toDisplay(mean.rgb), toDisplay(color), 1.0 / n));
    writeLayer(LAYER_MATERIAL, vec4(material.baseColorFactor.rgb, n / 255.0));
    writeLayer(LAYER_RADIANCE, vec4(color, 1.0));
}
