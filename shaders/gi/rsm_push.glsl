// Push constants of the reflective shadow map pass (render/gi/lpv.cpp: RsmPush).
layout(push_constant, scalar) uniform Push {
    mat4 viewProj;     // the light's view-projection
    uint64_t frame;
    uint light;        // index into the light buffer, 0xFFFFFFFF for the sun
    float texelArea;   // sun: world area of one texel (perpendicular to the sun)
    float texelSolidAngle; // spot: solid angle of the centre texel
} pc;
