#include "glint/graph/verify_rules.h"

#include <initializer_list>

namespace glint::rg::verify_rules {
namespace {

// Where a pass's shaders run (the spec's shader stages per pipeline type):
// a raster pass's descriptors may be read by its vertex or its fragment
// shader, so a write before it must reach both.
VkPipelineStageFlags2 shaderStages(Pipeline p) {
    switch (p) {
        case Pipeline::Compute:
            return VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
        case Pipeline::RayTracing:
            return VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR;
        case Pipeline::Raster:
            return VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
    }
    return VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
}

Need make(VkPipelineStageFlags2 stages, VkAccessFlags2 reads, VkAccessFlags2 writes, bool needsContents,
          std::initializer_list<VkImageLayout> layouts = {}) {
    Need n;
    n.stages = stages;
    n.reads = reads;
    n.writes = writes;
    n.needsContents = needsContents;
    for (const VkImageLayout l : layouts) n.layouts[n.layoutCount++] = l;
    return n;
}

// The transfer commands' stages (vkCmdCopy*, vkCmdBlitImage*, vkCmdResolveImage*
// read and write in their own stages; vkCmdClear*/vkCmdFillBuffer write in CLEAR).
constexpr VkPipelineStageFlags2 kTransferReadStages =
    VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_BLIT_BIT | VK_PIPELINE_STAGE_2_RESOLVE_BIT;
constexpr VkPipelineStageFlags2 kTransferWriteStages = kTransferReadStages | VK_PIPELINE_STAGE_2_CLEAR_BIT;
constexpr VkPipelineStageFlags2 kDepthTests =
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;

} // namespace

bool Need::allows(VkImageLayout layout) const {
    for (uint32_t i = 0; i < layoutCount; ++i)
        if (layouts[i] == layout) return true;
    return false;
}

Need need(Access access, ResourceKind kind, Pipeline pipeline) {
    const bool texture = kind == ResourceKind::Texture;
    const bool accel = kind == ResourceKind::AccelStruct;
    switch (access) {
        case Access::None:
        case Access::Count:
            return {};
        case Access::SampledRead:
            // A sampled image accepts the read-only layouts and GENERAL; a
            // "sampled" buffer is a uniform buffer.
            if (!texture) return make(shaderStages(pipeline), VK_ACCESS_2_UNIFORM_READ_BIT, 0, true);
            return make(shaderStages(pipeline), VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, 0, true,
                        {VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                         VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL,
                         VK_IMAGE_LAYOUT_GENERAL});
        case Access::StorageRead:
            // Storage images are only ever accessed in GENERAL.
            return make(shaderStages(pipeline), VK_ACCESS_2_SHADER_STORAGE_READ_BIT, 0, true,
                        {VK_IMAGE_LAYOUT_GENERAL});
        case Access::StorageWrite:
            return make(shaderStages(pipeline), 0, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, false,
                        {VK_IMAGE_LAYOUT_GENERAL});
        case Access::StorageReadWrite:
            return make(shaderStages(pipeline), VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
                        VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, true, {VK_IMAGE_LAYOUT_GENERAL});
        case Access::ColorAttachment:
            // Loads and blending read, stores write, all in the colour
            // attachment output stage; a clear load needs no contents.
            return make(VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT,
                        VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, false,
                        {VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL,
                         VK_IMAGE_LAYOUT_GENERAL});
        case Access::DepthWrite:
            return make(kDepthTests, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT,
                        VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, false,
                        {VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                         VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL});
        case Access::DepthRead:
            return make(kDepthTests, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT, 0, true,
                        {VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL,
                         VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                         VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL});
        case Access::IndirectArgs:
            // Draw, dispatch and trace-rays indirect all read their
            // parameters in the draw-indirect stage.
            return make(VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT, 0, true);
        case Access::TransferSrc:
            return make(kTransferReadStages, VK_ACCESS_2_TRANSFER_READ_BIT, 0, true,
                        {VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL});
        case Access::TransferDst:
            return make(kTransferWriteStages, 0, VK_ACCESS_2_TRANSFER_WRITE_BIT, false,
                        {VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL});
        case Access::AccelBuildInput:
            // Geometry, instance and transform data are read by the build
            // as shader reads; a structure it reads (an update's source, a
            // TLAS's BLASes) with the acceleration-structure read bit.
            return make(VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                        accel ? VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR : VK_ACCESS_2_SHADER_READ_BIT, 0,
                        true);
        case Access::AccelBuildWrite:
            // The destination is written (and read by an update); scratch
            // is read and written with the acceleration-structure bits.
            return make(VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                        VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR,
                        VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR, false);
        case Access::AccelRead:
            // Ray queries in any shader, trace rays in the ray tracing stage.
            return make(shaderStages(pipeline), VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR, 0, true);
        case Access::Present:
            // Presentation reads through the semaphore the frame signals:
            // the image must be in PRESENT_SRC before that signal.
            return make(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, 0, true, {VK_IMAGE_LAYOUT_PRESENT_SRC_KHR});
    }
    return {};
}

Need need(AccessSet kinds, ResourceKind kind, Pipeline pipeline) {
    Need out;
    bool first = true;
    for (uint32_t k = 0; k < kAccessCount; ++k) {
        if (!(kinds & (1u << k))) continue;
        const Need n = need(static_cast<Access>(k), kind, pipeline);
        out.stages |= n.stages;
        out.reads |= n.reads;
        out.writes |= n.writes;
        out.needsContents = out.needsContents || n.needsContents;
        if (first) {
            for (uint32_t i = 0; i < n.layoutCount; ++i) out.layouts[i] = n.layouts[i];
            out.layoutCount = n.layoutCount;
            first = false;
            continue;
        }
        // Layouts every kind of the set accepts.
        uint32_t kept = 0;
        for (uint32_t i = 0; i < out.layoutCount; ++i)
            if (n.allows(out.layouts[i])) out.layouts[kept++] = out.layouts[i];
        out.layoutCount = kept;
    }
    return out;
}

} // namespace glint::rg::verify_rules
