// Compile-time proof of the bare resource model: misuse of resources and views does not
// compile. Each static_assert states that an expression is ill-formed (or well-formed for the
// correct use, so the checks cannot pass vacuously). Building this file is the test.
#include <concepts>
#include <type_traits>

#include "rhi/gpu.h"
#include "rhi/resources.h"

namespace shadel {

// Stand-ins for the engine's consumers, with the signatures the real code uses.
void bindColor(RenderTargetView view);
void bindDepth(DepthTargetView view);
void sampleIn(TextureReadView view);
void writeIn(TextureWriteView view);

template <typename V>
concept BindableAsColor = requires(V v) {
    bindColor(v);
};
template <typename V>
concept BindableAsDepth = requires(V v) {
    bindDepth(v);
};
template <typename V>
concept Sampleable = requires(V v) {
    sampleIn(v);
};
template <typename V>
concept Writable = requires(V v) {
    writeIn(v);
};
template <typename H>
concept BufferAccess = requires(const Gpu& g, H h) {
    vkBuffer(g, h);
};
template <typename H>
concept ImageAccess = requires(const Gpu& g, H h) {
    vkImage(g, h);
};
template <typename H>
concept ReadViewSlot = requires(const Gpu& g, H h) {
    slot(g, h);
};

// A render target view binds as colour; nothing else does.
static_assert(BindableAsColor<RenderTargetView>);
static_assert(!BindableAsColor<TextureReadView>, "a read view must not bind as a render target");
static_assert(!BindableAsColor<TextureWriteView>);
static_assert(!BindableAsColor<DepthTargetView>);
static_assert(!BindableAsColor<TextureHandle>, "a texture must go through a view");

// Depth targets: only depth target views; a buffer is never a depth target.
static_assert(BindableAsDepth<DepthTargetView>);
static_assert(!BindableAsDepth<BufferHandle>, "a buffer must not be a depth target");
static_assert(!BindableAsDepth<RenderTargetView>);
static_assert(!BindableAsDepth<TextureHandle>);

// Shaders sample read views and write write views.
static_assert(Sampleable<TextureReadView>);
static_assert(!Sampleable<TextureWriteView>);
static_assert(!Sampleable<TextureHandle>);
static_assert(Writable<TextureWriteView>);
static_assert(!Writable<TextureReadView>);

// Buffers and textures are not interchangeable.
static_assert(BufferAccess<BufferHandle>);
static_assert(!BufferAccess<TextureHandle>,
              "a texture must not be used where a buffer is expected");
static_assert(ImageAccess<TextureHandle>);
static_assert(!ImageAccess<BufferHandle>);
static_assert(!ImageAccess<TextureReadView>);

// Only read and write views own bindless slots.
static_assert(ReadViewSlot<TextureReadView>);
static_assert(ReadViewSlot<TextureWriteView>);
static_assert(!ReadViewSlot<RenderTargetView>);
static_assert(!ReadViewSlot<BufferHandle>);

// No implicit conversions between handle kinds, in either direction.
static_assert(!std::is_convertible_v<TextureReadView, RenderTargetView>);
static_assert(!std::is_convertible_v<RenderTargetView, TextureReadView>);
static_assert(!std::is_convertible_v<BufferHandle, TextureHandle>);
static_assert(!std::is_convertible_v<uint32_t, BufferHandle>);
static_assert(!std::is_constructible_v<DepthTargetView, BufferHandle>);

} // namespace shadel
