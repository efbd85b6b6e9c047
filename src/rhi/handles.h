#pragma once
// The bare resource model: memory heaps, resources and views are separate concepts,
// and each view kind is its own type. A read view cannot be bound as a render target, a buffer
// cannot be a depth target, a texture is not a buffer: such mistakes do not compile.
#include <compare>
#include <cstdint>

namespace shadel {

template <typename Tag>
struct Handle {
    uint32_t index = ~0u;
    constexpr bool valid() const { return index != ~0u; }
    constexpr explicit operator bool() const { return valid(); }
    friend constexpr auto operator<=>(Handle, Handle) = default;
};

// Resources.
using BufferHandle = Handle<struct BufferTag>;
using TextureHandle = Handle<struct TextureTag>;

// Views of a texture, one type per use. Read and write views own a bindless slot.
using TextureReadView = Handle<struct TextureReadViewTag>;   // sampled in shaders
using TextureWriteView = Handle<struct TextureWriteViewTag>; // storage image (UAV)
using RenderTargetView = Handle<struct RenderTargetViewTag>; // colour attachment
using DepthTargetView = Handle<struct DepthTargetViewTag>;   // depth attachment

// Index of a view in the global bindless table, as shaders see it.
struct BindlessSlot {
    uint32_t value = 0;
};

} // namespace shadel
