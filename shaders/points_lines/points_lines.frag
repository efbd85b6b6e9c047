#version 460
// Unlit: the material's base colour factor times COLOR_0 is the radiance (render/points_lines).
layout(location = 0) in vec4 inColor;
layout(location = 0) out vec4 outColor;

void main() {
    outColor = vec4(inColor.rgb, 1.0);
}
