// The access table: what each named use means in sync2 terms.

#include <doctest/doctest.h>

#include "glint/graph/access.h"

using namespace glint::rg;

TEST_CASE("storage images live in GENERAL, read-only uses in READ_ONLY_OPTIMAL, attachments in ATTACHMENT_OPTIMAL") {
    for (Access a : {Access::StorageRead, Access::StorageWrite, Access::StorageReadWrite})
        CHECK((accessScope(a, ResourceKind::Texture, Pipeline::Compute).layout == VK_IMAGE_LAYOUT_GENERAL));
    for (Access a : {Access::SampledRead, Access::DepthRead})
        CHECK((accessScope(a, ResourceKind::Texture, Pipeline::Raster).layout == VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL));
    for (Access a : {Access::ColorAttachment, Access::DepthWrite})
        CHECK((accessScope(a, ResourceKind::Texture, Pipeline::Raster).layout == VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL));
    CHECK((accessScope(Access::TransferSrc, ResourceKind::Texture, Pipeline::Compute).layout ==
           VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL));
    CHECK((accessScope(Access::TransferDst, ResourceKind::Texture, Pipeline::Compute).layout ==
           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL));
    CHECK((accessScope(Access::StorageRead, ResourceKind::Buffer, Pipeline::Compute).layout ==
           VK_IMAGE_LAYOUT_UNDEFINED));
}

TEST_CASE("shader accesses take the stages of the pass's pipeline") {
    CHECK((accessScope(Access::SampledRead, ResourceKind::Texture, Pipeline::Compute).stages ==
           VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT));
    CHECK((accessScope(Access::SampledRead, ResourceKind::Texture, Pipeline::Raster).stages ==
           (VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT)));
    CHECK((accessScope(Access::AccelRead, ResourceKind::AccelStruct, Pipeline::RayTracing).stages ==
           VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR));
    CHECK((accessScope(Access::AccelRead, ResourceKind::AccelStruct, Pipeline::Compute).access ==
           VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR));
    // Fixed-function uses ignore the pipeline.
    CHECK((accessScope(Access::IndirectArgs, ResourceKind::Buffer, Pipeline::RayTracing).stages ==
           VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT));
    CHECK((accessScope(Access::ColorAttachment, ResourceKind::Texture, Pipeline::Raster).stages ==
           VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT));
}

TEST_CASE("acceleration-structure builds read buffer inputs as shader reads and write structures") {
    const SyncScope input = accessScope(Access::AccelBuildInput, ResourceKind::Buffer, Pipeline::Compute);
    CHECK(input.stages == VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR);
    CHECK(input.access == VK_ACCESS_2_SHADER_READ_BIT);
    const SyncScope blas = accessScope(Access::AccelBuildInput, ResourceKind::AccelStruct, Pipeline::Compute);
    CHECK(blas.access == VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
    const SyncScope build = accessScope(Access::AccelBuildWrite, ResourceKind::AccelStruct, Pipeline::Compute);
    CHECK((build.access & VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR) != 0);
    CHECK((accessWrites(Access::AccelBuildWrite)));
    CHECK_FALSE((accessWrites(Access::AccelBuildInput)));
}

TEST_CASE("merged read kinds union their stages and accesses") {
    const AccessSet both = accessBit(Access::DepthRead) | accessBit(Access::SampledRead);
    const SyncScope s = accessScope(both, ResourceKind::Texture, Pipeline::Raster);
    CHECK((s.stages & VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT) != 0);
    CHECK((s.stages & VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT) != 0);
    CHECK(s.access == (VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_SHADER_SAMPLED_READ_BIT));
    CHECK(s.layout == VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL);
}

TEST_CASE("usage flags follow the access kinds") {
    CHECK((imageUsageFor(accessBit(Access::SampledRead) | accessBit(Access::StorageWrite)) ==
           (VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT)));
    CHECK((imageUsageFor(accessBit(Access::DepthWrite)) == VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT));
    CHECK((bufferUsageFor(accessBit(Access::IndirectArgs) | accessBit(Access::StorageWrite)) ==
           (VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT)));
    CHECK((bufferUsageFor(accessBit(Access::AccelBuildInput)) &
           VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR) != 0);
}

TEST_CASE("the async compute queue has no attachments and no raster pipeline") {
    CHECK_FALSE((queueSupports(Queue::AsyncCompute, Access::ColorAttachment, Pipeline::Compute)));
    CHECK_FALSE((queueSupports(Queue::AsyncCompute, Access::DepthWrite, Pipeline::Compute)));
    CHECK_FALSE((queueSupports(Queue::AsyncCompute, Access::SampledRead, Pipeline::Raster)));
    CHECK((queueSupports(Queue::AsyncCompute, Access::StorageWrite, Pipeline::Compute)));
    CHECK((queueSupports(Queue::AsyncCompute, Access::AccelBuildWrite, Pipeline::Compute)));
    CHECK((queueSupports(Queue::AsyncCompute, Access::AccelRead, Pipeline::RayTracing)));
    CHECK((queueSupports(Queue::Graphics, Access::ColorAttachment, Pipeline::Raster)));
}

TEST_CASE("boundary states go through the table, raw ones pass their masks") {
    const SyncScope present = boundaryScope(BoundaryState::of(Access::Present), ResourceKind::Texture);
    CHECK(present.layout == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
    // No access (presentation reads through the semaphore), but the stages
    // of the semaphore signal, so the transition is inside its scope.
    CHECK(present.stages == kSemaphoreSignalStages);
    CHECK(present.access == VK_ACCESS_2_NONE);
    const SyncScope acquired =
        boundaryScope(BoundaryState::acquired(VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT), ResourceKind::Texture);
    CHECK(acquired.stages == VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT);
    CHECK(acquired.access == VK_ACCESS_2_NONE);
    CHECK(acquired.layout == VK_IMAGE_LAYOUT_UNDEFINED);
    const SyncScope raw =
        boundaryScope(BoundaryState::raw(VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, 0, VK_IMAGE_LAYOUT_UNDEFINED),
                      ResourceKind::Texture);
    CHECK(raw.stages == VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT);
    CHECK((BoundaryState::of(Access::SampledRead) == BoundaryState::of(Access::SampledRead)));
    CHECK_FALSE((BoundaryState::of(Access::SampledRead, Queue::Graphics) ==
                 BoundaryState::of(Access::SampledRead, Queue::AsyncCompute)));
}
