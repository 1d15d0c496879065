#include "glint/graph/access.h"

#include <array>
#include <bit>

namespace glint::rg {
namespace {

constexpr uint8_t kOnTexture = 1u << static_cast<uint32_t>(ResourceKind::Texture);
constexpr uint8_t kOnBuffer = 1u << static_cast<uint32_t>(ResourceKind::Buffer);
constexpr uint8_t kOnAccel = 1u << static_cast<uint32_t>(ResourceKind::AccelStruct);

struct Row {
    std::string_view name;
    bool needsContents = false;
    bool writes = false;
    bool boundaryOnly = false;
    bool needsRaster = false;
    uint8_t on = 0;      // resource kinds it applies to
    bool shader = false; // its stages are the shader stages of the pass's pipeline
    VkPipelineStageFlags2 stages = VK_PIPELINE_STAGE_2_NONE;
    VkAccessFlags2 textureAccess = 0;
    VkAccessFlags2 bufferAccess = 0;
    VkAccessFlags2 accelAccess = 0;
    VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
    VkImageUsageFlags imageUsage = 0;
    VkBufferUsageFlags bufferUsage = 0;
};

constexpr VkAccessFlags2 kStorageReadWrite = VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
constexpr VkAccessFlags2 kAccelReadWrite =
    VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
constexpr VkPipelineStageFlags2 kFragmentTests =
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;

// Layout choices:
// - Storage images live in GENERAL (Granite's rule; no layout games between
//   compute passes).
// - Read-only uses share VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL and attachments
//   ATTACHMENT_OPTIMAL (Vulkan 1.3 / synchronization2): they are
//   aspect-agnostic, so depth sampled and depth-tested in one pass needs no
//   split and colour/depth formats need no special case.
// - Acceleration-structure build inputs in buffers are read with SHADER_READ
//   at the build stage (vkCmdBuildAccelerationStructuresKHR's sync rules);
//   scratch is read and written with the ACCELERATION_STRUCTURE bits.
// Rows follow the Access enum.
constexpr std::array<Row, kAccessCount> kTable = {{
    {.name = "None", .boundaryOnly = true, .on = kOnTexture | kOnBuffer | kOnAccel},
    {.name = "SampledRead",
     .needsContents = true,
     .on = kOnTexture | kOnBuffer,
     .shader = true,
     .textureAccess = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
     .bufferAccess = VK_ACCESS_2_UNIFORM_READ_BIT,
     .layout = VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL,
     .imageUsage = VK_IMAGE_USAGE_SAMPLED_BIT,
     .bufferUsage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT},
    {.name = "StorageRead",
     .needsContents = true,
     .on = kOnTexture | kOnBuffer,
     .shader = true,
     .textureAccess = VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
     .bufferAccess = VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
     .layout = VK_IMAGE_LAYOUT_GENERAL,
     .imageUsage = VK_IMAGE_USAGE_STORAGE_BIT,
     .bufferUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT},
    {.name = "StorageWrite",
     .writes = true,
     .on = kOnTexture | kOnBuffer,
     .shader = true,
     .textureAccess = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
     .bufferAccess = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
     .layout = VK_IMAGE_LAYOUT_GENERAL,
     .imageUsage = VK_IMAGE_USAGE_STORAGE_BIT,
     .bufferUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT},
    {.name = "StorageReadWrite",
     .needsContents = true,
     .writes = true,
     .on = kOnTexture | kOnBuffer,
     .shader = true,
     .textureAccess = kStorageReadWrite,
     .bufferAccess = kStorageReadWrite,
     .layout = VK_IMAGE_LAYOUT_GENERAL,
     .imageUsage = VK_IMAGE_USAGE_STORAGE_BIT,
     .bufferUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT},
    // Attachments read too (load, blending, depth test) but may be a
    // frame's first use: a clear needs no contents.
    {.name = "ColorAttachment",
     .writes = true,
     .needsRaster = true,
     .on = kOnTexture,
     .stages = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
     .textureAccess = VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
     .layout = VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL,
     .imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT},
    {.name = "DepthWrite",
     .writes = true,
     .needsRaster = true,
     .on = kOnTexture,
     .stages = kFragmentTests,
     .textureAccess = VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
     .layout = VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL,
     .imageUsage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT},
    {.name = "DepthRead",
     .needsContents = true,
     .needsRaster = true,
     .on = kOnTexture,
     .stages = kFragmentTests,
     .textureAccess = VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT,
     .layout = VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL,
     .imageUsage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT},
    {.name = "IndirectArgs",
     .needsContents = true,
     .on = kOnBuffer,
     .stages = VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, // dispatch and trace-rays indirect read here too
     .bufferAccess = VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT,
     .bufferUsage = VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT},
    {.name = "TransferSrc",
     .needsContents = true,
     .on = kOnTexture | kOnBuffer,
     .stages = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
     .textureAccess = VK_ACCESS_2_TRANSFER_READ_BIT,
     .bufferAccess = VK_ACCESS_2_TRANSFER_READ_BIT,
     .layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
     .imageUsage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
     .bufferUsage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT},
    {.name = "TransferDst",
     .writes = true,
     .on = kOnTexture | kOnBuffer,
     .stages = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
     .textureAccess = VK_ACCESS_2_TRANSFER_WRITE_BIT,
     .bufferAccess = VK_ACCESS_2_TRANSFER_WRITE_BIT,
     .layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
     .imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT,
     .bufferUsage = VK_BUFFER_USAGE_TRANSFER_DST_BIT},
    {.name = "AccelBuildInput",
     .needsContents = true,
     .on = kOnBuffer | kOnAccel,
     .stages = VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
     .bufferAccess = VK_ACCESS_2_SHADER_READ_BIT,
     .accelAccess = VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR,
     .bufferUsage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                    VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT},
    // An update reads the structure it rewrites; a build's scratch is both.
    {.name = "AccelBuildWrite",
     .writes = true,
     .on = kOnBuffer | kOnAccel,
     .stages = VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
     .bufferAccess = kAccelReadWrite,
     .accelAccess = kAccelReadWrite,
     .bufferUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT},
    {.name = "AccelRead",
     .needsContents = true,
     .on = kOnAccel,
     .shader = true,
     .accelAccess = VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR},
    // No access: presentation reads through the semaphore. Its stages are
    // the semaphore signal's (kSemaphoreSignalStages says why).
    {.name = "Present",
     .needsContents = true,
     .boundaryOnly = true,
     .on = kOnTexture,
     .stages = kSemaphoreSignalStages,
     .layout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR},
}};

constexpr const Row& row(Access a) { return kTable[static_cast<uint32_t>(a)]; }

constexpr VkPipelineStageFlags2 shaderStagesOf(Pipeline p) {
    switch (p) {
        case Pipeline::Compute:
            return VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
        case Pipeline::Raster:
            return VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
        case Pipeline::RayTracing:
            return VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR;
    }
    return VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
}

constexpr VkAccessFlags2 kWriteBits =
    VK_ACCESS_2_SHADER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_HOST_WRITE_BIT |
    VK_ACCESS_2_MEMORY_WRITE_BIT | VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR |
    VK_ACCESS_2_TRANSFORM_FEEDBACK_WRITE_BIT_EXT | VK_ACCESS_2_TRANSFORM_FEEDBACK_COUNTER_WRITE_BIT_EXT |
    VK_ACCESS_2_COMMAND_PREPROCESS_WRITE_BIT_NV;

constexpr SyncScope computeScope(Access a, ResourceKind k, Pipeline p) {
    const Row& r = row(a);
    SyncScope s;
    s.stages = r.shader ? shaderStagesOf(p) : r.stages;
    switch (k) {
        case ResourceKind::Texture:
            s.access = r.textureAccess;
            s.layout = r.layout;
            break;
        case ResourceKind::Buffer:
            s.access = r.bufferAccess;
            break;
        case ResourceKind::AccelStruct:
            s.access = r.accelAccess;
            break;
    }
    return s;
}

constexpr detail::ScopeLut makeScopeLut() {
    detail::ScopeLut lut{};
    for (uint32_t a = 0; a < kAccessCount; ++a)
        for (uint32_t k = 0; k < 3; ++k)
            for (uint32_t p = 0; p < 3; ++p)
                lut.scope[a][k][p] =
                    computeScope(static_cast<Access>(a), static_cast<ResourceKind>(k), static_cast<Pipeline>(p));
    return lut;
}

constexpr detail::UsageLut makeUsageLut() {
    detail::UsageLut lut{};
    for (uint32_t half = 0; half < 2; ++half)
        for (uint32_t bits = 0; bits < 256; ++bits)
            for (uint32_t b = 0; b < 8; ++b) {
                const uint32_t a = half * 8 + b;
                if (!(bits & (1u << b)) || a >= kAccessCount) continue;
                lut.image[half][bits] |= kTable[a].imageUsage;
                lut.buffer[half][bits] |= kTable[a].bufferUsage;
            }
    return lut;
}

static_assert(row(Access::StorageReadWrite).name == "StorageReadWrite" && row(Access::AccelRead).name == "AccelRead" &&
                  row(Access::Present).name == "Present",
              "table rows follow the Access enum");

} // namespace

std::string_view toString(Access a) { return a < Access::Count ? row(a).name : std::string_view("?"); }

std::string_view toString(Queue q) { return q == Queue::Graphics ? "graphics" : "async-compute"; }

std::string_view toString(Pipeline p) {
    switch (p) {
        case Pipeline::Compute:
            return "compute";
        case Pipeline::Raster:
            return "raster";
        case Pipeline::RayTracing:
            return "ray-tracing";
    }
    return "?";
}

std::string_view toString(ResourceKind k) {
    switch (k) {
        case ResourceKind::Texture:
            return "texture";
        case ResourceKind::Buffer:
            return "buffer";
        case ResourceKind::AccelStruct:
            return "acceleration structure";
    }
    return "?";
}

namespace detail {

namespace {
constexpr std::array<AccessRules, kAccessCount> makeAccessRules() {
    std::array<AccessRules, kAccessCount> rules{};
    for (uint32_t a = 0; a < kAccessCount; ++a) {
        const Row& r = kTable[a];
        rules[a] = {r.on, r.needsContents, r.writes, r.boundaryOnly, r.needsRaster};
    }
    return rules;
}
constexpr std::array<AccessRules, kAccessCount> kRules = makeAccessRules();
} // namespace

constexpr AccessRules kAccessRules[kAccessCount] = {
    kRules[0], kRules[1], kRules[2],  kRules[3],  kRules[4],  kRules[5],  kRules[6],  kRules[7],
    kRules[8], kRules[9], kRules[10], kRules[11], kRules[12], kRules[13], kRules[14],
};
static_assert(kAccessCount == 15, "kAccessRules lists every row");

// Not const: tests corrupt entries (ScopeOverride) to show that the
// verifier, which has its own rules, rejects what a wrong entry compiles.
constinit ScopeLut kScopeLut = makeScopeLut();
constexpr UsageLut kUsageLut = makeUsageLut();

ScopeOverride::ScopeOverride(Access a, ResourceKind k, Pipeline p, const SyncScope& scope)
    : entry_(kScopeLut.scope[static_cast<uint32_t>(a)][static_cast<uint32_t>(k)][static_cast<uint32_t>(p)]),
      saved_(entry_),
      access_(a),
      kind_(k),
      pipeline_(p) {
    entry_ = scope;
    refreshUseInfo(a, k, p);
}

ScopeOverride::~ScopeOverride() {
    entry_ = saved_;
    refreshUseInfo(access_, kind_, pipeline_);
}
} // namespace detail

SyncScope accessScope(AccessSet set, ResourceKind k, Pipeline p) {
    SyncScope merged;
    for (AccessSet rest = set; rest; rest &= static_cast<AccessSet>(rest - 1)) {
        const SyncScope& one = scopeOf(static_cast<Access>(std::countr_zero(rest)), k, p);
        merged.stages |= one.stages;
        merged.access |= one.access;
        merged.layout = one.layout;
    }
    return merged;
}

VkAccessFlags2 writeAccessBits(VkAccessFlags2 access) { return access & kWriteBits; }
bool hasWriteAccess(VkAccessFlags2 access) { return (access & kWriteBits) != 0; }

} // namespace glint::rg
