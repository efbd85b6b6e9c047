// Misuse of the real rhi API must not compile. CTest compiles this file once per misuse
// (-DSHADEL_MISUSE=<name>) expecting failure, and once without a misuse expecting success:
// every misuse line has a correct twin in the well-formed part that calls the same function on
// the same variables, so a failure can only come from the wrong handle type.
#include "rhi/gpu.h"
#include "rhi/resources.h"

namespace shadel {

void useTheRealApi(Gpu& gpu, BufferHandle buffer, TextureHandle texture, TextureReadView readView,
                   TextureWriteView writeView, RenderTargetView renderTarget,
                   DepthTargetView depthTarget) {
    // The well-formed twins.
    (void)vkView(gpu, renderTarget);
    (void)vkView(gpu, depthTarget);
    (void)slot(gpu, readView);
    (void)slot(gpu, writeView);
    (void)vkBuffer(gpu, buffer);
    (void)vkImage(gpu, texture);
    (void)createReadView(gpu, texture);
    uploadBuffer(gpu, buffer, nullptr, 0);
    BufferHandle copy = buffer;
    (void)copy;

#if defined(SHADEL_MISUSE_read_view_as_render_target)
    (void)vkView(gpu, readView); // a sampled view is not an attachment
#elif defined(SHADEL_MISUSE_write_view_as_render_target)
    (void)vkView(gpu, writeView);
#elif defined(SHADEL_MISUSE_buffer_as_depth_target)
    (void)vkView(gpu, buffer);
#elif defined(SHADEL_MISUSE_texture_as_attachment_without_view)
    (void)vkView(gpu, texture);
#elif defined(SHADEL_MISUSE_render_target_has_no_slot)
    (void)slot(gpu, renderTarget);
#elif defined(SHADEL_MISUSE_texture_as_buffer)
    (void)vkBuffer(gpu, texture);
#elif defined(SHADEL_MISUSE_buffer_as_image)
    (void)vkImage(gpu, buffer);
#elif defined(SHADEL_MISUSE_view_of_a_buffer)
    (void)createReadView(gpu, buffer);
#elif defined(SHADEL_MISUSE_upload_into_texture_as_buffer)
    uploadBuffer(gpu, texture, nullptr, 0);
#elif defined(SHADEL_MISUSE_integer_as_handle)
    BufferHandle fromInteger = 5u;
    (void)fromInteger;
#elif defined(SHADEL_MISUSE_handle_kinds_convert)
    TextureHandle fromBuffer = buffer;
    (void)fromBuffer;
#elif defined(SHADEL_MISUSE_read_view_as_write_view)
    TextureWriteView fromRead = readView;
    (void)fromRead;
#endif
}

} // namespace shadel
