// Stencil bits of the stencil-culled effects (render/stencil), shared by C++ and GLSL.
#ifndef SHADEL_STENCIL_BITS_H
#define SHADEL_STENCIL_BITS_H

#define STENCIL_WATER 1u             // a visible water pixel: the water composite
#define STENCIL_CHARACTER 2u         // a character fragment lies here, seen or hidden: outline
#define STENCIL_CHARACTER_VISIBLE 4u // ... and it is the visible surface (no occlusion tint)

// The character mask (R8) the outline reads its neighbours from: 0 none, this for a character
// hidden behind something, 1 for a visible one.
#define CHARACTER_MASK_HIDDEN 0.5

#endif
