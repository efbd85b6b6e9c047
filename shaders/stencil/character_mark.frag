#version 460
// Stencil marks (render/stencil): the stencil ops do the work; the colour is the character mask
// (max-blended, so a visible character wins over one hidden behind it).
#include "stencil/stencil_bits.h"

layout(constant_id = 0) const float kMaskValue = 1.0;

layout(location = 0) out float outMask;

void main() { outMask = kMaskValue; }
