#include "glint/passes/feedback.h"

#include "glint/gpu/error.h"

#include <cmath>
#include <string>

namespace glint::passes {

shader::FeedbackConstants feedbackConstants(const FeedbackSettings& settings, uint32_t width, uint32_t height,
                                            uint64_t frameIndex, bool resetHistory) {
    const auto fraction = [](float f) { return f >= 0.0f && f <= 1.0f; };
    if (!fraction(settings.sslrMissFraction) || !fraction(settings.rtHitFraction)) {
        throw gpu::GpuError("feedback: sslrMissFraction and rtHitFraction must lie in [0, 1] (got " +
                            std::to_string(settings.sslrMissFraction) + ", " + std::to_string(settings.rtHitFraction) +
                            ")");
    }
    if (!fraction(settings.sslrMinHitShare) || settings.sslrProbeInterval == 0) {
        throw gpu::GpuError("feedback: sslrMinHitShare must lie in [0, 1] and sslrProbeInterval be at least 1 (got " +
                            std::to_string(settings.sslrMinHitShare) + ", " +
                            std::to_string(settings.sslrProbeInterval) + ")");
    }
    shader::FeedbackConstants constants{};
    constants.size = {width, height};
    constants.tiles = {(width + shader::kTileSize - 1) / shader::kTileSize,
                       (height + shader::kTileSize - 1) / shader::kTileSize};
    // The same 32-bit frame as the rest of the noise (glint/sampling.glsl).
    constants.frame = uint32_t(frameIndex);
    constants.minRays = settings.minRays;
    constants.sslrMissFraction = settings.sslrMissFraction;
    constants.rtHitFraction = settings.rtHitFraction;
    constants.adaptive = settings.adaptive ? 1u : 0u;
    constants.resetHistory = resetHistory ? 1u : 0u;
    constants.minFrameHits = uint32_t(std::ceil(double(settings.sslrMinHitShare) * double(width) * double(height)));
    constants.probeInterval = settings.sslrProbeInterval;
    return constants;
}

} // namespace glint::passes
