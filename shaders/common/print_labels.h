// Labels of shader print records (shaders/common/shader_print.glsl), shared by GLSL and C++ (the
// decoder in rhi/shader_messages.cpp names each one): GLSL has no strings, so a print carries a
// label id and the CPU prints its text. Add new labels at the end.
#ifndef SHADEL_PRINT_LABELS_H
#define SHADEL_PRINT_LABELS_H
#define PRINT_INSPECT_PIXEL 1u    // the pixel under --inspect (internal resolution)
#define PRINT_INSTANCE 2u         // instance index
#define PRINT_TRIANGLE 3u         // triangle (within its mesh: gl_PrimitiveID of LOD 0 draws)
#define PRINT_POSITION 4u         // world position
#define PRINT_GEOMETRIC_NORMAL 5u // interpolated vertex normal, world
#define PRINT_UV_LOD 6u           // log2 of the UV footprint in texels (forward MIP)
#define PRINT_BASE_COLOR 7u       // material: base colour
#define PRINT_ROUGHNESS 8u        // material: perceptual roughness
#define PRINT_METALLIC 9u         // material: metallic
#define PRINT_SHADING_NORMAL 10u  // material: normal (normal map applied)
#define PRINT_OCCLUSION 11u       // material: occlusion
#define PRINT_EMISSIVE 12u        // term: emissive
#define PRINT_AMBIENT 13u         // term: the environment (image-based lighting)
#define PRINT_SUN_SHADOW 14u      // the sun's PCF shadow factor
#define PRINT_SUN 15u             // term: the sun
#define PRINT_LIGHT 16u           // term: one punctual light (rgb, index)
#define PRINT_SHADED 17u          // shadeSurface's result (sum of the terms)
#define PRINT_SHADEL_LOD 18u      // decoupled: shadel LOD (MIP + blend), first MIP, second MIP
#define PRINT_SHADEL_CHUNK 19u    // decoupled: sheet chunk x, y, storage slot, MIP
#define PRINT_RECONSTRUCTED 20u   // decoupled: radiance read back from the shade storage
#define PRINT_OUTPUT 21u          // the colour the pass wrote for this pixel
#define PRINT_FRAGMENT_DEPTH 22u  // gl_FragCoord.z: of several fragments, the CPU shows the front
#define PRINT_SHADING_BIAS 23u    // decoupled: frame's shading bias, material rate, texture LOD
#define PRINT_TEST 100u           // used by the tests
#define PRINT_LABEL_COUNT 101u
#define SHADER_PRINT_BIT 0x80000000u // ShaderMessage::assertId of a print: this | label
#define PRINT_UINT 0u // ShaderMessage::format: type | count << 4 | invocation tag << 8
#define PRINT_INT 1u
#define PRINT_FLOAT 2u
#define INSPECT_OFF 0xFFFFFFFFu // FrameConstants::inspectPixel when --inspect is not given
#define INSPECT_MAX_LIGHTS 16u  // punctual lights printed per pixel (the message buffer is small)
#endif
