#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <spdlog/spdlog.h>

#include <cstdlib>

int main(int argc, char** argv) {
    // Quiet by default; GLINT_LOG=debug (or trace, info, ...) for detail.
    const char* level = std::getenv("GLINT_LOG");
    spdlog::set_level(level ? spdlog::level::from_str(level) : spdlog::level::warn);
    doctest::Context context(argc, argv);
    return context.run();
}
