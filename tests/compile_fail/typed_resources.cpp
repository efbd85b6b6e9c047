// Compile-time proof of the bare resource model: misuse of resources and views does not
// compile. Each static_assert states that an expression is ill-formed (or well-formed for the
// correct use, so the checks cannot pass vacuously). Building this file is the test.
#include <concepts>
#include <type_traits>

#include "rhi/gpu.h"
#include "rhi/resources.h"

namespace shadel {

// Each concept asks whether the real rhi API (rhi/resources.h) accepts a handle kind.
template <typename V>
concept Attachable = requires(const Gpu& g, V v) { // a colour or depth attachment's image view
    { vkView(g, v) } -> std::same_as<VkImageView>;
};
template <typename V>
concept Sampleable = requires(const Gpu& g, V v) {
    { sampledImageView(g, v) } -> std::same_as<VkImageView>;
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
concept BindlessSlotOf = requires(const Gpu& g, H h) {
    { slot(g, h) } -> std::same_as<BindlessSlot>;
};
template <typename H>
concept ViewOfATexture = requires(const Gpu& g, H h) {
    { textureOf(g, h) } -> std::same_as<TextureHandle>;
};

// Render target and depth target views bind as attachments; nothing else does.
static_assert(Attachable<RenderTargetView>);
static_assert(Attachable<DepthTargetView>);
static_assert(!Attachable<TextureReadView>, "a read view must not bind as a render target");
static_assert(!Attachable<TextureWriteView>);
static_assert(!Attachable<TextureHandle>, "a texture must go through a view");
static_assert(!Attachable<BufferHandle>, "a buffer must not be a depth target");

// Only read views are sampled through an image view.
static_assert(Sampleable<TextureReadView>);
static_assert(!Sampleable<TextureWriteView>);
static_assert(!Sampleable<RenderTargetView>);
static_assert(!Sampleable<TextureHandle>);

// Buffers and textures are not interchangeable.
static_assert(BufferAccess<BufferHandle>);
static_assert(!BufferAccess<TextureHandle>,
              "a texture must not be used where a buffer is expected");
static_assert(ImageAccess<TextureHandle>);
static_assert(!ImageAccess<BufferHandle>);
static_assert(!ImageAccess<TextureReadView>);

// Only read and write views own bindless slots.
static_assert(BindlessSlotOf<TextureReadView>);
static_assert(BindlessSlotOf<TextureWriteView>);
static_assert(!BindlessSlotOf<RenderTargetView>);
static_assert(!BindlessSlotOf<BufferHandle>);

// Every view knows its texture; a buffer is no view.
static_assert(ViewOfATexture<TextureReadView> && ViewOfATexture<TextureWriteView>);
static_assert(ViewOfATexture<RenderTargetView> && ViewOfATexture<DepthTargetView>);
static_assert(!ViewOfATexture<BufferHandle>);

// No implicit conversions between handle kinds, in either direction.
static_assert(!std::is_convertible_v<TextureReadView, RenderTargetView>);
static_assert(!std::is_convertible_v<RenderTargetView, TextureReadView>);
static_assert(!std::is_convertible_v<RenderTargetView, DepthTargetView>);
static_assert(!std::is_convertible_v<TextureReadView, TextureWriteView>);
static_assert(!std::is_convertible_v<BufferHandle, TextureHandle>);
static_assert(!std::is_convertible_v<uint32_t, BufferHandle>);
static_assert(!std::is_constructible_v<DepthTargetView, BufferHandle>);

} // namespace shadel
