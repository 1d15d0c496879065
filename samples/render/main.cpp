// glint-render: the headless renderer. Until the reflection pipeline lands
// it renders the smoke scene with every ray backend the device has and
// writes one PNG per backend.

#include "common/app.h"
#include "passes/smoke_trace.h"

#include <spdlog/spdlog.h>

using namespace glint;

int main(int argc, char** argv) {
    return app::runMain("glint-render", [&] {
        app::Args args(argc, argv, "usage: glint-render [--scene smoke] [--size N] [--out DIR]", {"scene", "size", "out"},
                       {});
        const std::string sceneName = args.get("scene", "smoke");
        if (sceneName != "smoke") {
            throw std::runtime_error("--scene " + sceneName + ": unknown scene (available: smoke)");
        }
        const uint32_t size = args.getUint("size", 256);
        if (size == 0 || size > 8192) {
            throw std::runtime_error("--size " + std::to_string(size) + ": must be 1..8192");
        }
        const std::string outDir = args.get("out", "build/out");

        gpu::Context ctx(args.contextOptions());
        passes::SmokeTracer tracer(ctx, scene::makeSmokeScene());
        for (auto backend : passes::availableBackends(ctx)) {
            const auto result = tracer.trace(backend, size, size);
            const std::string path = outDir + "/smoke_" + passes::backendName(backend) + ".png";
            app::writePng(path, size, size, passes::smokeImage(result.hits, size, size));
            if (result.gpuMilliseconds) {
                spdlog::info("{}: {:.3f} ms GPU, {:.2f} Mrays/s", passes::backendName(backend), *result.gpuMilliseconds,
                             double(size) * size / (*result.gpuMilliseconds * 1e3));
            }
        }
        ctx.waitIdle();
        return app::validationClean(ctx) ? 0 : 2;
    });
}
