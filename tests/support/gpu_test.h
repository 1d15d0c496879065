#pragma once
// A Vulkan context for GPU tests: validation layer with synchronization
// validation on; the test fails on any message it collects (checked when the
// fixture goes away, after the device is destroyed, so leaks count too).

#include "glint/gpu/context.h"

#include <doctest/doctest.h>

#include <memory>

namespace glint::test {

class GpuTest {
public:
    explicit GpuTest(gpu::ContextOptions options = {}) {
        options.validation = true;
        ctx_ = std::make_unique<gpu::Context>(options);
        log_ = ctx_->validationLog();
    }
    ~GpuTest() {
        if (ctx_) {
            finish();
        }
    }
    GpuTest(const GpuTest&) = delete;
    GpuTest& operator=(const GpuTest&) = delete;

    gpu::Context& ctx() { return *ctx_; }
    gpu::ValidationLog& log() { return *log_; }

    // Destroys the device and checks that validation said nothing.
    void finish() {
        ctx_.reset();
        CHECK_MESSAGE(log_->count() == 0, log_->summary());
    }

private:
    std::unique_ptr<gpu::Context> ctx_;
    std::shared_ptr<gpu::ValidationLog> log_;
};

} // namespace glint::test
