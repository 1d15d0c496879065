#include "glint/scene/image_io.h"

#include "glint/scene/error.h"

// The implementation is compiled into libstb (libstb-dev); only declarations here.
#include <stb_image.h>
#include <stb_image_write.h>

#include <climits>
#include <fstream>
#include <memory>

namespace glint::scene {

std::vector<uint8_t> readFileLimited(const std::filesystem::path& path, uint64_t maxBytes, const std::string& file,
                                     const std::string& element) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
        throw SceneError(file, element, "file not found: " + path.string());
    }
    const uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) {
        throw SceneError(file, element, "cannot read " + path.string() + ": " + ec.message());
    }
    if (size > maxBytes) {
        throw SceneError(file, element,
                         path.string() + " has " + std::to_string(size) + " bytes, more than the limit of " +
                             std::to_string(maxBytes));
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        throw SceneError(file, element, "cannot open " + path.string());
    }
    std::vector<uint8_t> data(static_cast<size_t>(size));
    in.read(reinterpret_cast<char*>(data.data()), std::streamsize(size));
    if (in.gcount() != std::streamsize(size)) {
        throw SceneError(file, element, "short read of " + path.string());
    }
    return data;
}

namespace {

struct StbiFree {
    void operator()(void* p) const { stbi_image_free(p); }
};

std::string failureReason() {
    const char* reason = stbi_failure_reason();
    return reason ? reason : "unknown stb_image error";
}

// Reads the header and checks it against the limits; returns width, height.
glm::uvec2 checkedImageSize(std::span<const uint8_t> bytes, const ImageLimits& limits, size_t bytesPerTexel,
                            const std::string& file, const std::string& element) {
    if (bytes.empty()) {
        throw SceneError(file, element, "image data is empty");
    }
    if (bytes.size() > size_t(INT_MAX)) {
        throw SceneError(file, element, "encoded image larger than 2 GiB");
    }
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(bytes.data(), int(bytes.size()), &w, &h, &comp)) {
        throw SceneError(file, element, "cannot decode image: " + failureReason());
    }
    if (w <= 0 || h <= 0 || uint32_t(w) > limits.maxDimension || uint32_t(h) > limits.maxDimension) {
        throw SceneError(file, element,
                         "image is " + std::to_string(w) + " x " + std::to_string(h) + ", beyond the limit of " +
                             std::to_string(limits.maxDimension));
    }
    const uint64_t decoded = uint64_t(w) * uint64_t(h) * bytesPerTexel;
    if (decoded > limits.maxBytes) {
        throw SceneError(file, element,
                         "image would decode to " + std::to_string(decoded) + " bytes, beyond the limit of " +
                             std::to_string(limits.maxBytes));
    }
    return {uint32_t(w), uint32_t(h)};
}

} // namespace

Texture decodeImageRgba8(std::span<const uint8_t> bytes, const ImageLimits& limits, const std::string& file,
                         const std::string& element) {
    const glm::uvec2 size = checkedImageSize(bytes, limits, 4, file, element);
    int w = 0, h = 0, comp = 0;
    std::unique_ptr<stbi_uc, StbiFree> pixels(stbi_load_from_memory(bytes.data(), int(bytes.size()), &w, &h, &comp, 4));
    if (!pixels || uint32_t(w) != size.x || uint32_t(h) != size.y) {
        throw SceneError(file, element, "cannot decode image: " + failureReason());
    }
    Texture t;
    t.width = size.x;
    t.height = size.y;
    t.format = TextureFormat::Rgba8;
    t.rgba8.assign(pixels.get(), pixels.get() + size_t(size.x) * size.y * 4);
    return t;
}

Texture decodeImageRgba32f(std::span<const uint8_t> bytes, const ImageLimits& limits, const std::string& file,
                           const std::string& element) {
    const glm::uvec2 size = checkedImageSize(bytes, limits, 16, file, element);
    int w = 0, h = 0, comp = 0;
    std::unique_ptr<float, StbiFree> pixels(stbi_loadf_from_memory(bytes.data(), int(bytes.size()), &w, &h, &comp, 4));
    if (!pixels || uint32_t(w) != size.x || uint32_t(h) != size.y) {
        throw SceneError(file, element, "cannot decode image: " + failureReason());
    }
    Texture t;
    t.width = size.x;
    t.height = size.y;
    t.format = TextureFormat::Rgba32Float;
    t.rgba32f.assign(pixels.get(), pixels.get() + size_t(size.x) * size.y * 4);
    return t;
}

Environment loadEquirectangularEnvironment(const std::filesystem::path& path, const ImageLimits& limits) {
    const std::string file = path.string();
    const std::vector<uint8_t> bytes = readFileLimited(path, limits.maxBytes, file, "");
    Environment env;
    env.kind = EnvironmentKind::EquirectangularImage;
    env.image = decodeImageRgba32f(bytes, limits, file, "");
    env.image.name = path.filename().string();
    if (env.image.width != 2 * env.image.height) {
        throw SceneError(file, "",
                         "an equirectangular image is twice as wide as high; this one is " +
                             std::to_string(env.image.width) + " x " + std::to_string(env.image.height));
    }
    return env;
}

void writePng(const std::filesystem::path& path, uint32_t width, uint32_t height, std::span<const uint8_t> rgba) {
    if (width == 0 || height == 0 || rgba.size() < size_t(width) * height * 4) {
        throw SceneError(path.string(), "", "writePng: " + std::to_string(rgba.size()) + " bytes are not " +
                                                std::to_string(width) + "x" + std::to_string(height) + " RGBA8 pixels");
    }
    if (path.has_parent_path()) {
        std::error_code ec;
        std::filesystem::create_directories(path.parent_path(), ec);
        if (ec) throw SceneError(path.string(), "", "cannot make the folder: " + ec.message());
    }
    if (!stbi_write_png(path.c_str(), int(width), int(height), 4, rgba.data(), int(width * 4))) {
        throw SceneError(path.string(), "", "cannot write the PNG");
    }
}

} // namespace glint::scene
