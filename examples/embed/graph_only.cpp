// Glint::graph on its own: a frame of three passes declared, compiled and
// checked by the plan verifier, on a machine with no GPU and no Vulkan
// loader (the library uses Vulkan's types, never its calls).
#include <glint/graph/graph.h>
#include <glint/graph/verify.h>

#include <cstdio>

using namespace glint;

int main() {
    // A device with an async compute family apart from graphics.
    rg::QueueCaps caps;
    caps.separateComputeFamily = true;
    caps.computeFamily = 1;
    rg::Graph graph(caps);
    const rg::TextureDesc hdr{640, 360, 1, 1, 1, VK_FORMAT_R16G16B16A16_SFLOAT};
    rg::Texture lit;
    graph.addPass("lighting", rg::Queue::Graphics, [&](rg::Builder& b) {
        lit = b.write(b.createTexture("lit", hdr), rg::Access::StorageWrite);
    });
    rg::Texture blurred;
    graph.addPass("blur", rg::Queue::AsyncCompute, [&](rg::Builder& b) {
        b.read(lit, rg::Access::SampledRead);
        blurred = b.write(b.createTexture("blurred", hdr), rg::Access::StorageWrite);
    });
    graph.addPass("composite", rg::Queue::Graphics, [&](rg::Builder& b) {
        b.read(blurred, rg::Access::SampledRead);
        b.markSideEffects();
    });
    const rg::Plan plan = graph.compile();
    const rg::VerifyReport report = rg::verify(plan);
    std::printf("%s\n", plan.toText().c_str());
    std::printf("verifier: %s\n", report.ok() ? "ok" : report.text().c_str());
    return report.ok() ? 0 : 1;
}
