#version 460
// --debug-lines lights|blockers: one invocation per light (its range sphere, spot cone, tube
// segment or area light's rectangle; with blockers, the shadow frustum of every blocker it lists, from the light through
// the blocker's corners out to its range), then one per blocker (its rectangle and portals).
// With --debug-lines-at X,Y only the lights whose reach holds the surface point at that pixel.
#include "debug/debug_lines.glsl"
#include "common/lighting.glsl"
#include "lighting/light_cull.glsl"

layout(local_size_x = 64) in;
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    int atX, atY;   // --debug-lines-at (internal pixel), -1: off
    uint depthSlot; // the frame's depth, sampled when atX >= 0
} pc;

// The surface point seen at pixel (atX, atY); w = 0 for the sky.
vec4 pickedSurface(FrameConstants f) {
    float depth = fetchTextureUniform(pc.depthSlot, ivec2(pc.atX, pc.atY), 0).r;
    if (depth <= 0.0) return vec4(0.0); // reversed Z: the sky
    vec2 ndc = (vec2(pc.atX, pc.atY) + 0.5) * f.invViewportSize * 2.0 - 1.0;
    vec4 w = f.invViewProj * vec4(ndc, depth, 1.0);
    return vec4(w.xyz / w.w, 1.0);
}

// Whether the light reaches the surface seen at the picked pixel; never for the sky.
bool reachesPickedSurface(FrameConstants f, GpuLight light) {
    vec4 p = pickedSurface(f);
    vec4 sphere = lightSphere(light);
    return p.w != 0.0 && (sphere.w < 0.0 || distance(p.xyz, sphere.xyz) <= sphere.w);
}

vec3 lightColour(GpuLight light) {
    if ((light.flags & LIGHT_FLAG_DARK) != 0u) return vec3(1.0, 0.0, 1.0); // darks: magenta
    vec3 c = abs(light.color);
    return c / max(max(c.r, max(c.g, c.b)), 1e-6);
}

// Two unit vectors orthogonal to d (and to each other).
void basis(vec3 d, out vec3 u, out vec3 v) {
    u = normalize(abs(d.y) < 0.9 ? cross(d, vec3(0, 1, 0)) : cross(d, vec3(1, 0, 0)));
    v = cross(d, u);
}

void emitLight(FrameConstants f, GpuLight light) {
    vec3 colour = lightColour(light);
    if (light.type == LIGHT_DIRECTIONAL) return;
    float reach = light.range > 0.0 ? light.range : 10.0; // infinite range: a 10 m marker
    if (light.type == LIGHT_SPOT || light.type == LIGHT_SPOT_SQUARE) {
        // The outer cone where spotFactor reaches 0 (shaders/common/lighting.glsl).
        float tanOuter;
        if (light.type == LIGHT_SPOT) {
            float cosOuter = clamp(-light.spotOffset / light.spotScale, 0.01, 1.0);
            tanOuter = sqrt(1.0 - cosOuter * cosOuter) / cosOuter;
        } else {
            tanOuter = light.spotOffset / light.spotScale;
        }
        vec3 u, v;
        basis(light.direction, u, v);
        if (light.type == LIGHT_SPOT_SQUARE) u = light.axis, v = cross(light.direction, light.axis);
        vec3 base = light.position + light.direction * reach;
        float r = reach * tanOuter;
        if (light.type == LIGHT_SPOT) {
            debugCircle(f, base, u, v, r, colour, 24u);
            for (int k = 0; k < 4; ++k) {
                float a = 1.5707963 * float(k);
                debugLine(f, light.position, base + (u * cos(a) + v * sin(a)) * r, colour);
            }
        } else {
            debugRect(f, base, u * r, v * r, colour);
            for (int k = 0; k < 4; ++k)
                debugLine(f, light.position,
                          base + u * r * ((k & 1) != 0 ? 1.0 : -1.0) + v * r * ((k & 2) != 0 ? 1.0 : -1.0),
                          colour);
        }
        return;
    }
    if (light.type == LIGHT_AREA) { // the rectangle and the way it emits
        vec3 up = cross(light.direction, light.axis);
        debugRect(f, light.position, light.axis * light.halfLength, up * light.radius, colour);
        debugLine(f, light.position, light.position + light.direction * min(reach, 1.0), colour);
        return;
    }
    if (light.type == LIGHT_TUBE)
        debugLine(f, light.position - light.axis * light.halfLength,
                  light.position + light.axis * light.halfLength, colour);
    debugSphere(f, light.position, reach, colour);
}

void emitBlockerFrusta(FrameConstants f, LightingFrame lf, GpuLight light) {
    if (light.type == LIGHT_DIRECTIONAL) return;
    UintBuffer list = UintBuffer(lf.lightBlockers);
    LightBlockerBuffer blockers = LightBlockerBuffer(lf.blockers);
    for (uint k = 0u; k < light.blockerCount; ++k) {
        GpuLightBlocker b = blockers.b[list.v[light.blockerFirst + k]];
        for (int c = 0; c < 4; ++c) {
            vec3 corner = b.center + b.axisU * b.halfU * ((c & 1) != 0 ? 1.0 : -1.0) +
                          b.axisV * b.halfV * ((c & 2) != 0 ? 1.0 : -1.0);
            vec3 dir = corner - light.position;
            float reach = light.range > 0.0 ? light.range : 2.0 * length(dir);
            debugLine(f, corner, light.position + normalize(dir) * max(reach, length(dir)),
                      vec3(1.0, 0.55, 0.1));
        }
    }
}

void emitBlocker(FrameConstants f, LightingFrame lf, GpuLightBlocker b) {
    debugRect(f, b.center, b.axisU * b.halfU, b.axisV * b.halfV, vec3(1.0, 0.2, 0.1));
    LightPortalBuffer portals = LightPortalBuffer(lf.portals);
    for (uint k = 0u; k < b.portalCount; ++k) {
        GpuLightPortal p = portals.p[b.firstPortal + k];
        // Portal rectangles are in metres along the blocker's axes from its centre (blockerStops).
        vec2 lo = p.minUv, hi = p.maxUv;
        vec3 centre = b.center + b.axisU * 0.5 * (lo.x + hi.x) + b.axisV * 0.5 * (lo.y + hi.y);
        debugRect(f, centre, b.axisU * 0.5 * (hi.x - lo.x), b.axisV * 0.5 * (hi.y - lo.y),
                  vec3(0.2, 1.0, 0.3));
    }
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    uint i = gl_GlobalInvocationID.x;
    bool lights = debugLinesOn(f, DEBUG_LINES_LIGHTS), blockers = debugLinesOn(f, DEBUG_LINES_BLOCKERS);
    LightingFrame lf;
    uint blockerCount = 0u;
    if (f.lighting != 0ul) {
        lf = LightingFrameRef(f.lighting).l;
        blockerCount = lf.blockerCount;
    }
    if (i == 0u && pc.atX >= 0) { // the picked point: a small magenta cross
        vec4 p = pickedSurface(f);
        float r = 0.15;
        if (p.w != 0.0)
            for (int a = 0; a < 3; ++a) {
                vec3 axis = vec3(a == 0, a == 1, a == 2) * r;
                debugLine(f, p.xyz - axis, p.xyz + axis, vec3(1.0, 0.0, 1.0));
            }
    }
    if (i < f.lightCount) {
        GpuLight light = LightBuffer(f.lights).l[i];
        // Only lights whose range meets the camera frustum (the lines are for what one sees).
        vec4 sphere = vec4(light.position, light.range > 0.0 ? light.range : 1e30);
        for (int k = 0; k < 6; ++k)
            if (dot(f.frustumPlanes[k].xyz, sphere.xyz) + f.frustumPlanes[k].w < -sphere.w) return;
        if (pc.atX >= 0 && !reachesPickedSurface(f, light)) return;
        if (lights) emitLight(f, light);
        if (blockers && f.lighting != 0ul) emitBlockerFrusta(f, lf, light);
    } else if (blockers && i - f.lightCount < blockerCount) {
        emitBlocker(f, lf, LightBlockerBuffer(lf.blockers).b[i - f.lightCount]);
    }
}
