#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <dlfcn.h>

#if defined(__SANITIZE_ADDRESS__)
// The validation layer and lavapipe keep allocations until exit and are
// unloaded before LeakSanitizer looks; their leaks then come from an
// "unknown module" that no suppression (tests/support/lsan.supp) can name.
// Keeping them loaded lets the suppressions match while our own leaks
// still fail the run.
static void pinDriverLibraries() {
    for (const char* lib : {"libVkLayer_khronos_validation.so", "libvulkan_lvp.so"}) {
        dlopen(lib, RTLD_NOW | RTLD_GLOBAL | RTLD_NODELETE);
    }
}
#else
static void pinDriverLibraries() {}
#endif

int main(int argc, char** argv) {
    pinDriverLibraries();
    // Quiet by default; GLINT_LOG=debug (or trace, info, ...) for detail.
    const char* level = std::getenv("GLINT_LOG");
    spdlog::set_level(level ? spdlog::level::from_str(level) : spdlog::level::warn);
    doctest::Context context(argc, argv);
    return context.run();
}
