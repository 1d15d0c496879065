// glTF files: reading, the GLB container, a JSON preflight, then tinygltf.
//
// tinygltf parses but does not validate: it trusts GLB chunk lengths a
// little too far, reads image bufferViews without checking their range, and
// recurses on JSON nesting. So before tinygltf sees a byte, this file checks
// the GLB container itself, bounds the JSON nesting depth, and checks every
// buffer's declared size against the data that is really there and every
// image bufferView against its buffer. The
// conversion to the scene model (gltf_convert.cpp) then checks every
// accessor before reading it (gltf_accessors.cpp).

#include "glint/scene/gltf_internal.h"

#include "glint/scene/animation.h"
#include "glint/scene/error.h"
#include "glint/scene/image_io.h"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <optional>
#include <span>
#include <string_view>

namespace glint::scene {

bool isSupportedGltfExtension(std::string_view name) {
    static constexpr std::array<std::string_view, 5> kSupported = {"KHR_materials_emissive_strength",
                                                                   "KHR_lights_punctual", "KHR_materials_ior",
                                                                   "KHR_mesh_quantization", "KHR_texture_transform"};
    return std::find(kSupported.begin(), kSupported.end(), name) != kSupported.end();
}

namespace gltf {

void LoadContext::chargeDecoded(uint64_t bytes, const std::string& element) {
    if (bytes > options.maxDecodedBytes || decodedBytes > options.maxDecodedBytes - bytes) {
        throw SceneError(file, element,
                         "decoding " + std::to_string(bytes) + " more bytes would pass the limit of " +
                             std::to_string(options.maxDecodedBytes) + " decoded bytes");
    }
    decodedBytes += bytes;
}

std::string decodeUri(const std::string& uri) {
    const auto hex = [](char c) -> int {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10;
        return 0;
    };
    std::string out;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '+') {
            out += ' ';
        } else if (uri[i] == '%' && i + 2 < uri.size()) {
            out += char((hex(uri[i + 1]) << 4) | hex(uri[i + 2]));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

} // namespace gltf

namespace {

using gltf::LoadContext;
using Json = nlohmann::json;

static_assert(std::endian::native == std::endian::little, "GLB fields are read as little-endian integers");

constexpr uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr uint32_t kGlbChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kGlbChunkBin = 0x004E4942;   // "BIN\0"
constexpr size_t kGlbHeaderBytes = 12;
constexpr size_t kGlbChunkHeaderBytes = 8;

uint32_t readU32(const uint8_t* p) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

void appendU32(std::vector<uint8_t>& out, uint32_t v) {
    const auto* p = reinterpret_cast<const uint8_t*>(&v);
    out.insert(out.end(), p, p + 4);
}

struct GlbChunks {
    std::span<const uint8_t> json;
    std::optional<std::span<const uint8_t>> bin;
    // What tinygltf gets: the file itself (up to the declared length) when it
    // is laid out as tinygltf expects - the JSON chunk, then BIN right after,
    // nothing else - otherwise a rebuilt copy in that layout.
    std::span<const uint8_t> original;
    std::vector<uint8_t> rebuilt;

    std::span<const uint8_t> forTinygltf() const {
        return rebuilt.empty() ? original : std::span<const uint8_t>(rebuilt);
    }
};

// Walks the GLB container (glTF 2.0, section 4.4) checking every length
// against the bytes that exist.
GlbChunks parseGlb(std::span<const uint8_t> bytes, const std::string& file) {
    if (bytes.size() < kGlbHeaderBytes) {
        throw SceneError(file, "GLB header",
                         "file has " + std::to_string(bytes.size()) + " bytes; the header alone needs 12");
    }
    const uint32_t version = readU32(bytes.data() + 4);
    const uint32_t length = readU32(bytes.data() + 8);
    if (version != 2) {
        throw SceneError(file, "GLB header", "version " + std::to_string(version) + " (only 2 is supported)");
    }
    if (length > bytes.size()) {
        throw SceneError(file, "GLB header",
                         "declares " + std::to_string(length) + " bytes but the file has " +
                             std::to_string(bytes.size()) + " (truncated?)");
    }
    GlbChunks chunks;
    size_t offset = kGlbHeaderBytes;
    bool canonical = true;
    for (uint32_t index = 0; offset < length; ++index) {
        const std::string element = "GLB chunk " + std::to_string(index);
        if (length - offset < kGlbChunkHeaderBytes) {
            throw SceneError(file, element,
                             "header at byte " + std::to_string(offset) + " runs past the end (" +
                                 std::to_string(length) + " bytes)");
        }
        const uint32_t chunkLength = readU32(bytes.data() + offset);
        const uint32_t chunkType = readU32(bytes.data() + offset + 4);
        const size_t payload = offset + kGlbChunkHeaderBytes;
        if (chunkLength > length - payload) {
            throw SceneError(file, element,
                             "declares " + std::to_string(chunkLength) + " bytes but only " +
                                 std::to_string(length - payload) + " remain");
        }
        const std::span<const uint8_t> data = bytes.subspan(payload, chunkLength);
        if (index == 0) {
            if (chunkType != kGlbChunkJson) {
                throw SceneError(file, element, "the first chunk must be JSON");
            }
            if (chunkLength == 0) {
                throw SceneError(file, element, "the JSON chunk is empty");
            }
            chunks.json = data;
        } else if (chunkType == kGlbChunkBin) {
            if (chunks.bin) {
                throw SceneError(file, element, "a second BIN chunk");
            }
            if (chunkLength == 0 || chunkLength % 4 != 0) {
                throw SceneError(file, element,
                                 "BIN chunk length " + std::to_string(chunkLength) +
                                     " is not a positive multiple of 4");
            }
            canonical = canonical && index == 1;
            chunks.bin = data;
        } else {
            canonical = false;  // unknown chunk types are skipped (glTF 2.0, 4.4.3.1)
        }
        offset = payload + chunkLength;
    }
    if (chunks.json.empty()) {
        throw SceneError(file, "GLB", "no JSON chunk");
    }
    if (canonical) {
        chunks.original = bytes.first(length);
        return chunks;
    }
    // JSON + BIN only, which is the layout tinygltf can read.
    std::vector<uint8_t>& out = chunks.rebuilt;
    const size_t jsonPadded = (chunks.json.size() + 3) & ~size_t(3);
    appendU32(out, kGlbMagic);
    appendU32(out, 2);
    appendU32(out, 0);  // total length, patched below
    appendU32(out, uint32_t(jsonPadded));
    appendU32(out, kGlbChunkJson);
    out.insert(out.end(), chunks.json.begin(), chunks.json.end());
    out.resize(out.size() + (jsonPadded - chunks.json.size()), uint8_t(' '));
    if (chunks.bin) {
        appendU32(out, uint32_t(chunks.bin->size()));
        appendU32(out, kGlbChunkBin);
        out.insert(out.end(), chunks.bin->begin(), chunks.bin->end());
    }
    const uint32_t total = uint32_t(out.size());
    std::memcpy(out.data() + 8, &total, 4);
    return chunks;
}

// Parsers recurse on nesting; refuse deep nesting before any parser runs.
void checkJsonDepth(std::span<const uint8_t> text, uint32_t maxDepth, const std::string& file) {
    bool inString = false;
    bool escaped = false;
    uint32_t depth = 0;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = char(text[i]);
        if (inString) {
            if (escaped) {
                escaped = false;
            } else if (c == '\\') {
                escaped = true;
            } else if (c == '"') {
                inString = false;
            }
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > maxDepth) {
                throw SceneError(file, "JSON",
                                 "nesting deeper than " + std::to_string(maxDepth) + " levels at byte " +
                                     std::to_string(i));
            }
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
}

const Json* member(const Json& object, const char* key) {
    const auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
}

uint64_t nonNegativeInteger(const Json& value, const std::string& file, const std::string& element, const char* what) {
    if (value.is_number_unsigned()) {
        return value.get<uint64_t>();
    }
    if (value.is_number_integer() && value.get<int64_t>() >= 0) {
        return uint64_t(value.get<int64_t>());
    }
    throw SceneError(file, element, std::string(what) + " must be a non-negative integer, not " + value.dump());
}

// Bytes a base64 payload decodes to, or nullopt if it is not plain base64.
std::optional<uint64_t> base64DecodedSize(std::string_view payload) {
    if (payload.size() % 4 != 0) {
        return std::nullopt;
    }
    size_t padding = 0;
    for (size_t i = 0; i < payload.size(); ++i) {
        const char c = payload[i];
        const bool alnum =
            (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '+' || c == '/';
        if (c == '=' && i + 2 >= payload.size()) {
            ++padding;
        } else if (!alnum || padding > 0) {
            return std::nullopt;
        }
    }
    return uint64_t(payload.size() / 4 * 3 - padding);
}

// The data-URI headers tinygltf decodes for buffers.
constexpr std::array<std::string_view, 2> kBufferDataUriHeaders = {"data:application/octet-stream;base64,",
                                                                   "data:application/gltf-buffer;base64,"};

// Checks the parts of the document tinygltf trusts: version, required
// extensions, and each buffer's byteLength against the data really there.
void preflight(const Json& doc, const std::filesystem::path& baseDir, std::optional<size_t> binChunkBytes,
               LoadContext& context) {
    const std::string& file = context.file;
    if (!doc.is_object()) {
        throw SceneError(file, "JSON", "the top level is not an object");
    }
    const Json* asset = member(doc, "asset");
    const Json* version = asset && asset->is_object() ? member(*asset, "version") : nullptr;
    if (!version || !version->is_string()) {
        throw SceneError(file, "asset", "no asset.version; not a glTF 2.0 file");
    }
    const std::string versionText = version->get<std::string>();
    if (versionText.rfind("2.", 0) != 0) {
        throw SceneError(file, "asset", "version '" + versionText + "' (only glTF 2.x is supported)");
    }
    if (const Json* required = member(doc, "extensionsRequired")) {
        if (!required->is_array()) {
            throw SceneError(file, "extensionsRequired", "is not an array");
        }
        for (const Json& ext : *required) {
            const std::string name = ext.is_string() ? ext.get<std::string>() : ext.dump();
            if (!isSupportedGltfExtension(name)) {
                throw SceneError(file, "extensionsRequired",
                                 "the file requires " + name + ", which Glint does not support");
            }
        }
    }
    if (const Json* buffers = member(doc, "buffers")) {
        if (!buffers->is_array()) {
            throw SceneError(file, "buffers", "is not an array");
        }
        for (size_t i = 0; i < buffers->size(); ++i) {
            const Json& buffer = (*buffers)[i];
            const std::string element = "buffer " + std::to_string(i);
            if (!buffer.is_object()) {
                throw SceneError(file, element, "is not an object");
            }
            const Json* byteLength = member(buffer, "byteLength");
            if (!byteLength) {
                throw SceneError(file, element, "has no byteLength");
            }
            const uint64_t declared = nonNegativeInteger(*byteLength, file, element, "byteLength");
            const Json* uri = member(buffer, "uri");
            if (!uri) {
                if (!binChunkBytes || i != 0) {
                    throw SceneError(file, element, "has no uri (only buffer 0 of a .glb may use the BIN chunk)");
                }
                if (declared > *binChunkBytes) {
                    throw SceneError(file, element,
                                     "byteLength " + std::to_string(declared) + " exceeds the GLB BIN chunk (" +
                                         std::to_string(*binChunkBytes) + " bytes)");
                }
                if (declared == 0) {
                    throw SceneError(file, element, "byteLength is 0");
                }
                continue;
            }
            if (!uri->is_string()) {
                throw SceneError(file, element, "uri is not a string");
            }
            const std::string text = uri->get<std::string>();
            if (text.rfind("data:", 0) == 0) {
                const auto header = std::find_if(kBufferDataUriHeaders.begin(), kBufferDataUriHeaders.end(),
                                                 [&](std::string_view h) { return text.rfind(h, 0) == 0; });
                if (header == kBufferDataUriHeaders.end()) {
                    throw SceneError(file, element, "data URI is not application/octet-stream or gltf-buffer base64");
                }
                const std::optional<uint64_t> size = base64DecodedSize(std::string_view(text).substr(header->size()));
                if (!size) {
                    throw SceneError(file, element, "data URI is not valid base64");
                }
                if (*size != declared) {
                    throw SceneError(file, element,
                                     "data URI holds " + std::to_string(*size) + " bytes but byteLength is " +
                                         std::to_string(declared));
                }
                continue;
            }
            const std::filesystem::path path = baseDir / gltf::decodeUri(text);
            std::error_code ec;
            if (!std::filesystem::is_regular_file(path, ec)) {
                throw SceneError(file, element + " ('" + text + "')", "file not found: " + path.string());
            }
            const uintmax_t actual = std::filesystem::file_size(path, ec);
            if (ec || actual != declared) {
                throw SceneError(file, element + " ('" + text + "')",
                                 "byteLength is " + std::to_string(declared) + " but the file has " +
                                     std::to_string(actual) + " bytes" + (actual < declared ? " (truncated?)" : ""));
            }
            if (actual > context.options.maxFileBytes) {
                throw SceneError(file, element + " ('" + text + "')",
                                 std::to_string(actual) + " bytes, more than the limit of " +
                                     std::to_string(context.options.maxFileBytes));
            }
        }
    }
    // Images in bufferViews: tinygltf computes a pointer from the view's
    // offset before anything checks it, so check view and buffer here.
    const Json* views = member(doc, "bufferViews");
    const Json* buffers = member(doc, "buffers");
    if (const Json* images = member(doc, "images"); images && images->is_array()) {
        for (size_t i = 0; i < images->size(); ++i) {
            const Json& image = (*images)[i];
            const Json* view = image.is_object() ? member(image, "bufferView") : nullptr;
            if (view) {
                const std::string element = "image " + std::to_string(i);
                const uint64_t v = nonNegativeInteger(*view, file, element, "bufferView");
                if (!views || !views->is_array() || v >= views->size() || !(*views)[v].is_object()) {
                    throw SceneError(file, element, "bufferView " + std::to_string(v) + " out of range");
                }
                const Json& bv = (*views)[v];
                const Json* bufferIndex = member(bv, "buffer");
                const uint64_t b = bufferIndex ? nonNegativeInteger(*bufferIndex, file, element, "buffer") : ~0ull;
                if (!buffers || !buffers->is_array() || b >= buffers->size()) {
                    throw SceneError(file, element, "bufferView " + std::to_string(v) + " refers to a missing buffer");
                }
                const Json* byteLength = member((*buffers)[b], "byteLength");
                const uint64_t bufferBytes =
                    byteLength ? nonNegativeInteger(*byteLength, file, element, "byteLength") : 0;
                const Json* offsetJson = member(bv, "byteOffset");
                const Json* lengthJson = member(bv, "byteLength");
                const uint64_t offset = offsetJson ? nonNegativeInteger(*offsetJson, file, element, "byteOffset") : 0;
                const uint64_t length = lengthJson ? nonNegativeInteger(*lengthJson, file, element, "byteLength") : 0;
                if (offset > bufferBytes || length > bufferBytes - offset) {
                    throw SceneError(file, element,
                                     "bufferView " + std::to_string(v) + " (byteOffset " + std::to_string(offset) +
                                         " + byteLength " + std::to_string(length) + ") exceeds buffer " +
                                         std::to_string(b) + " (" + std::to_string(bufferBytes) + " bytes)");
                }
                continue;
            }
            const Json* uri = image.is_object() ? member(image, "uri") : nullptr;
            if (!uri || !uri->is_string() || uri->get<std::string>().rfind("data:", 0) == 0) {
                continue;
            }
            const std::filesystem::path path = baseDir / gltf::decodeUri(uri->get<std::string>());
            std::error_code ec;
            if (!std::filesystem::is_regular_file(path, ec)) {
                context.missingImages[int(i)] = "file not found: " + path.string();
            }
        }
    }
}

// ---------------------------------------------------------------------------
// tinygltf callbacks
// ---------------------------------------------------------------------------

bool fsFileExists(const std::string& path, void*) {
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
}

// No tilde or variable expansion: a URI names a file relative to the glTF.
std::string fsExpandPath(const std::string& path, void*) {
    return path;
}

bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    const auto* context = static_cast<const LoadContext*>(user);
    try {
        *out = readFileLimited(path, context->options.maxFileBytes, context->file, "");
        return true;
    } catch (const SceneError& e) {
        if (err) {
            *err = e.what();
        }
        return false;
    }
}

bool fsWriteWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) {
        *err = "the loader does not write files";
    }
    return false;
}

// Keeps the encoded bytes of URI images for decoding after validation.
// bufferView images are skipped: tinygltf hands over a pointer computed
// from an unchecked byteOffset, which must not be dereferenced.
bool captureImage(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                  const unsigned char* bytes, int size, void* user) {
    auto* context = static_cast<LoadContext*>(user);
    if (image->bufferView >= 0 || !context->options.loadTextures || index < 0 || !bytes || size <= 0) {
        return true;
    }
    context->encodedImages[index].assign(bytes, bytes + size);
    return true;
}

std::string firstLines(const std::string& text, size_t maxLines = 3) {
    std::string out;
    size_t lines = 0;
    for (char c : text) {
        if (c == '\n') {
            if (++lines == maxLines) {
                break;
            }
            out += "; ";
        } else {
            out += c;
        }
    }
    while (!out.empty() && (out.back() == ' ' || out.back() == ';')) {
        out.pop_back();
    }
    return out;
}

// ---------------------------------------------------------------------------
// The initial view
// ---------------------------------------------------------------------------

// A view that frames the scene bounds, for files without a camera.
void frameBounds(Scene& scene) {
    const Aabb bounds = sceneBounds(scene);
    const glm::vec3 center = bounds.empty() ? glm::vec3(0.0f) : bounds.center();
    const float radius = bounds.empty() ? 1.0f : std::max(0.5f * glm::length(bounds.size()), 1e-6f);
    const float fov = glm::radians(45.0f);
    const float distance = radius / std::sin(fov * 0.5f);
    scene.lens.verticalFovRadians = fov;
    scene.lens.nearPlane = 0.5f * (distance - radius);
    scene.lens.farPlane = kInfiniteFar;
    scene.cameraPath.keys = {{0.0f, center + glm::normalize(glm::vec3(0.0f, 0.25f, 1.0f)) * distance, center}};
}

} // namespace

Scene loadGltf(const std::filesystem::path& path, const GltfLoadOptions& options) {
    LoadContext context;
    context.file = path.string();
    context.options = options;
    const std::string& file = context.file;
    if (options.maxFileBytes >= (1ull << 32)) {
        throw SceneError(file, "", "GltfLoadOptions::maxFileBytes must stay below 4 GiB (tinygltf reads 32-bit sizes)");
    }

    const std::vector<uint8_t> bytes = readFileLimited(path, options.maxFileBytes, file, "");
    const bool binary = bytes.size() >= 4 && readU32(bytes.data()) == kGlbMagic;
    GlbChunks glb;
    std::span<const uint8_t> jsonText(bytes);
    if (binary) {
        glb = parseGlb(bytes, file);
        jsonText = glb.json;
    }
    if (jsonText.empty()) {
        throw SceneError(file, "JSON", "file is empty");
    }
    checkJsonDepth(jsonText, options.maxJsonDepth, file);
    Json doc;
    try {
        doc = Json::parse(jsonText.begin(), jsonText.end());
    } catch (const Json::exception& e) {
        throw SceneError(file, "JSON", e.what());
    }
    const std::filesystem::path baseDir = path.parent_path();
    preflight(doc, baseDir, glb.bin ? std::optional<size_t>(glb.bin->size()) : std::nullopt, context);

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(&captureImage, &context);
    loader.SetFsCallbacks({&fsFileExists, &fsExpandPath, &fsReadWholeFile, &fsWriteWholeFile, &context});
    tinygltf::Model model;
    std::string err;
    std::string warn;
    bool ok = false;
    try {
        // An empty base directory makes tinygltf look relative to the
        // working directory, which is what a relative `path` means.
        const std::string base = baseDir.string();
        const std::span<const uint8_t> container = glb.forTinygltf();
        ok = binary
                 ? loader.LoadBinaryFromMemory(&model, &err, &warn, container.data(), unsigned(container.size()), base)
                 : loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                              unsigned(bytes.size()), base);
    } catch (const std::exception& e) {
        throw SceneError(file, "glTF", e.what());
    }
    if (!warn.empty()) {
        spdlog::debug("{}: tinygltf: {}", file, firstLines(warn, 20));
    }
    if (!ok) {
        throw SceneError(file, "glTF",
                         err.empty() ? std::string("tinygltf could not parse the file") : firstLines(err));
    }
    // tinygltf also reports schema problems it recovered from (a property of
    // the wrong type or length, replaced by its default): one warning each.
    std::set<std::string> reported;
    for (size_t begin = 0; begin < err.size();) {
        const size_t end = std::min(err.find('\n', begin), err.size());
        const std::string line = err.substr(begin, end - begin);
        // tinygltf 2.7 calls a skin without inverseBindMatrices an error;
        // glTF 2.0 makes them optional (identity matrices).
        const bool specValid = line.find("'inverseBindMatrices' property is missing") != std::string::npos;
        if (line.empty() || !reported.insert(line).second) {
            // nothing new
        } else if (specValid) {
            spdlog::debug("{}: tinygltf: {}", file, line);
        } else {
            spdlog::warn("{}: glTF: {} (default used)", file, line);
        }
        begin = end + 1;
    }

    std::set<std::string> seen;
    for (const std::string& ext : model.extensionsUsed) {
        if (!seen.insert(ext).second) {
            continue;
        }
        if (isSupportedGltfExtension(ext)) {
            spdlog::debug("{}: using glTF extension {}", file, ext);
        } else {
            spdlog::info("{}: ignoring glTF extension {} (not supported)", file, ext);
        }
    }

    Scene scene = gltf::convertModel(model, context);
    scene.name = file;
    if (options.reflectionLods) {
        const ReflectionLodStats lods = generateReflectionLods(scene, *options.reflectionLods);
        if (lods.meshes > 0) {
            spdlog::info("{}: reflection LODs for {} meshes: {} -> {} triangles (largest relative error {:.4f})", file,
                         lods.meshes, lods.trianglesBefore, lods.trianglesAfter, lods.largestError);
        }
    }
    prepareScene(scene);
    if (scene.cameraPath.keys.empty()) {
        frameBounds(scene);
    }
    spdlog::debug("{}: {} meshes, {} materials, {} textures, {} instances, {} triangles ({} instanced), {} MiB decoded",
                  file, scene.meshes.size(), scene.materials.size(), scene.textures.size(), scene.instances.size(),
                  meshTriangleCount(scene), instancedTriangleCount(scene), context.decodedBytes >> 20);
    return scene;
}

} // namespace glint::scene
