// The verifier has its own rules (glint/graph/verify_rules.h): corrupt one
// entry of the compiler's access table at a time (its stages, its access
// mask, its layout) and the plans compiled with it, which agree with the
// wrong entry, must be rejected.

#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "glint/graph/verify_rules.h"
#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

namespace {

// One use under test: `access` on a resource of `kind` from a pass on
// `pipeline`, with a partner use that writes before it (when it reads) or
// reads after it (when it writes).
struct Case {
    const char* name;
    Access access;
    ResourceKind kind;
    Pipeline pipeline;
    Access partner;
    Pipeline partnerPipeline;
    VkFormat format = VK_FORMAT_R16G16B16A16_SFLOAT;
};

bool writes(Access a) {
    return a == Access::StorageWrite || a == Access::StorageReadWrite || a == Access::ColorAttachment ||
           a == Access::DepthWrite || a == Access::TransferDst || a == Access::AccelBuildWrite;
}

// writer -> reader of one resource on one queue; the reader has side
// effects, so nothing is culled.
Plan compileCase(const Case& c) {
    Graph g(oneQueue());
    const Access write = writes(c.access) ? c.access : c.partner;
    const Access read = writes(c.access) ? c.partner : c.access;
    const Pipeline writePipeline = writes(c.access) ? c.pipeline : c.partnerPipeline;
    const Pipeline readPipeline = writes(c.access) ? c.partnerPipeline : c.pipeline;
    const auto declare = [&](auto resource) {
        auto written = resource;
        if (c.access == Access::StorageReadWrite) {  // reads: something must be there
            g.addPass("filler", Queue::Graphics, [&](Builder& b) { written = b.write(written, Access::StorageWrite); });
        }
        g.addPass("writer", Queue::Graphics, [&](Builder& b) {
            b.setPipeline(writePipeline);
            written = b.write(written, write);
        });
        g.addPass("reader", Queue::Graphics, [&](Builder& b) {
            b.setPipeline(readPipeline);
            b.read(written, read);
            b.markSideEffects();
        });
    };
    switch (c.kind) {
        case ResourceKind::Texture:
            declare(g.createTexture("t", tex(64, c.format)));
            break;
        case ResourceKind::Buffer:
            declare(g.createBuffer("b", {4096}));
            break;
        case ResourceKind::AccelStruct:
            declare(g.importAccelStruct(
                "tlas", {BoundaryState::of(Access::AccelRead), BoundaryState::of(Access::AccelRead)}));
            break;
    }
    return compile(g, oneQueue());
}

// A stage set disjoint from `stages`.
VkPipelineStageFlags2 otherStage(VkPipelineStageFlags2 stages) {
    return (stages & VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT) ? VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT
                                                              : VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
}

// A layout the use's own rules do not accept.
VkImageLayout wrongLayout(const Case& c) {
    const verify_rules::Need need = verify_rules::need(c.access, c.kind, c.pipeline);
    for (const VkImageLayout l : {VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                  VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL})
        if (!need.allows(l)) return l;
    FAIL("no wrong layout");
    return VK_IMAGE_LAYOUT_UNDEFINED;
}

const std::vector<Case> kCases = {
    {"sampled texture, compute", Access::SampledRead, ResourceKind::Texture, Pipeline::Compute, Access::StorageWrite,
     Pipeline::Compute},
    {"sampled texture, raster", Access::SampledRead, ResourceKind::Texture, Pipeline::Raster, Access::StorageWrite,
     Pipeline::Compute},
    {"storage texture read, ray tracing", Access::StorageRead, ResourceKind::Texture, Pipeline::RayTracing,
     Access::StorageWrite, Pipeline::Compute},
    {"storage texture read-write", Access::StorageReadWrite, ResourceKind::Texture, Pipeline::Compute,
     Access::SampledRead, Pipeline::Compute},
    {"storage texture write", Access::StorageWrite, ResourceKind::Texture, Pipeline::Compute, Access::SampledRead,
     Pipeline::Compute},
    {"colour attachment", Access::ColorAttachment, ResourceKind::Texture, Pipeline::Raster, Access::SampledRead,
     Pipeline::Compute},
    {"depth write", Access::DepthWrite, ResourceKind::Texture, Pipeline::Raster, Access::SampledRead,
     Pipeline::Compute, VK_FORMAT_D32_SFLOAT},
    {"depth test", Access::DepthRead, ResourceKind::Texture, Pipeline::Raster, Access::DepthWrite, Pipeline::Raster,
     VK_FORMAT_D32_SFLOAT},
    {"texture copy source", Access::TransferSrc, ResourceKind::Texture, Pipeline::Compute, Access::StorageWrite,
     Pipeline::Compute},
    {"texture copy destination", Access::TransferDst, ResourceKind::Texture, Pipeline::Compute, Access::SampledRead,
     Pipeline::Compute},
    {"uniform buffer", Access::SampledRead, ResourceKind::Buffer, Pipeline::Compute, Access::StorageWrite,
     Pipeline::Compute},
    {"storage buffer read", Access::StorageRead, ResourceKind::Buffer, Pipeline::Compute, Access::StorageWrite,
     Pipeline::Compute},
    {"storage buffer write", Access::StorageWrite, ResourceKind::Buffer, Pipeline::Compute, Access::StorageRead,
     Pipeline::Compute},
    {"indirect arguments", Access::IndirectArgs, ResourceKind::Buffer, Pipeline::Compute, Access::StorageWrite,
     Pipeline::Compute},
    {"buffer copy source", Access::TransferSrc, ResourceKind::Buffer, Pipeline::Compute, Access::StorageWrite,
     Pipeline::Compute},
    {"buffer copy destination", Access::TransferDst, ResourceKind::Buffer, Pipeline::Compute, Access::StorageRead,
     Pipeline::Compute},
    {"build input buffer", Access::AccelBuildInput, ResourceKind::Buffer, Pipeline::Compute, Access::StorageWrite,
     Pipeline::Compute},
    {"build scratch", Access::AccelBuildWrite, ResourceKind::Buffer, Pipeline::Compute, Access::StorageRead,
     Pipeline::Compute},
    {"structure build", Access::AccelBuildWrite, ResourceKind::AccelStruct, Pipeline::Compute, Access::AccelRead,
     Pipeline::Compute},
    {"ray query", Access::AccelRead, ResourceKind::AccelStruct, Pipeline::Compute, Access::AccelBuildWrite,
     Pipeline::Compute},
    {"trace rays", Access::AccelRead, ResourceKind::AccelStruct, Pipeline::RayTracing, Access::AccelBuildWrite,
     Pipeline::Compute},
    {"structure read by a build", Access::AccelBuildInput, ResourceKind::AccelStruct, Pipeline::Compute,
     Access::AccelBuildWrite, Pipeline::Compute},
};

} // namespace

TEST_CASE("each case compiles to a plan the verifier accepts while the compiler's table is right") {
    for (const Case& c : kCases) {
        const std::string label(c.name);
        INFO(label);
        const Plan plan = compileCase(c);
        const VerifyReport report = verify(plan);
        INFO(plan.toText());
        CHECK_MESSAGE(report.ok(), report.text());
    }
}

TEST_CASE("a wrong stage, access mask or layout in the compiler's table makes plans the verifier rejects") {
    uint32_t corrupted = 0;
    for (const Case& c : kCases) {
        const SyncScope right = accessScope(c.access, c.kind, c.pipeline);
        std::vector<std::pair<std::string, SyncScope>> wrongs;
        SyncScope s = right;
        s.stages = otherStage(right.stages);
        wrongs.emplace_back("stages", s);
        s = right;
        s.access = VK_ACCESS_2_NONE;
        wrongs.emplace_back("access mask", s);
        if (c.kind == ResourceKind::Texture) {
            s = right;
            s.layout = wrongLayout(c);
            wrongs.emplace_back("layout", s);
        }
        for (const auto& [what, wrong] : wrongs) {
            const std::string label = std::string(c.name) + ": " + what;
            INFO(label);
            // The wrong entry stays in place while the verifier runs: a
            // verifier that read the compiler's table would agree with it.
            const detail::ScopeOverride corrupt(c.access, c.kind, c.pipeline, wrong);
            const Plan plan = compileCase(c);
            const VerifyReport report = verify(plan);
            INFO(plan.toText());
            CHECK_FALSE(report.ok());
            ++corrupted;
        }
    }
    CHECK(corrupted == 2 * kCases.size() + 10);  // ten texture cases also get a wrong layout
}
