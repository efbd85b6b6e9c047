// Shader assert ids, shared by GLSL (the SHADEL_ASSERT macro) and C++ (the decoder prints the
// message). Add new ids at the end; the C++ table in rhi/shader_messages.cpp names each one.
#ifndef SHADEL_ASSERTS_H
#define SHADEL_ASSERTS_H
#define ASSERT_INSTANCE_RANGE 1u // instance index out of range
#define ASSERT_MATERIAL_RANGE 2u // material index out of range
#define ASSERT_DRAW_OVERFLOW 3u  // more draws than the indirect buffer holds
#define ASSERT_NON_FINITE 4u     // non-finite shading result
#define ASSERT_SHADEL_SLOT 5u    // shadel storage slot out of range
#define ASSERT_TRIANGLE_ID 6u    // triangle id out of range
#define ASSERT_SHADE_PIPELINE 7u // a shading pipeline without a part this frame uses
#define ASSERT_TEST 100u         // used by the tests to prove the channel works
#endif
