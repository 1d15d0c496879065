#pragma once
// Helpers shared by the scene suites: where the shared scenes and the test
// outputs live, a log capture to count warnings, file I/O, and a small glTF
// fixture builder for documents the shared scenes do not cover (skins,
// animations, extensions).

#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <glm/glm.hpp>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace glint::test {

using Json = nlohmann::json;

inline std::filesystem::path scenesDir() {
    return GLINT_SCENES_DIR;
}

// A fresh folder under the build tree for files a test generates.
inline std::filesystem::path outputDir(const std::string& name) {
    const std::filesystem::path dir = std::filesystem::path(GLINT_TEST_OUTPUT_DIR) / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

inline std::vector<uint8_t> readBytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    REQUIRE_MESSAGE(in.good(), "cannot read " << path);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void writeBytes(const std::filesystem::path& path, const void* data, size_t size) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(static_cast<const char*>(data), std::streamsize(size));
    REQUIRE_MESSAGE(out.good(), "cannot write " << path);
}

inline void writeBytes(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
    writeBytes(path, bytes.data(), bytes.size());
}

inline void writeText(const std::filesystem::path& path, const std::string& text) {
    writeBytes(path, text.data(), text.size());
}

inline Json readJson(const std::filesystem::path& path) {
    std::ifstream in(path);
    return Json::parse(in);
}

// The JSON chunk of a .glb, read independently of the loader.
inline Json readGlbJson(const std::filesystem::path& path) {
    const std::vector<uint8_t> bytes = readBytes(path);
    REQUIRE(bytes.size() >= 20);
    uint32_t length = 0;
    std::memcpy(&length, bytes.data() + 12, 4);
    REQUIRE(20 + size_t(length) <= bytes.size());
    return Json::parse(bytes.begin() + 20, bytes.begin() + 20 + length);
}

// Routes spdlog's default logger into a string while alive.
class LogCapture {
public:
    LogCapture() : previous_(spdlog::default_logger()) {
        auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(stream_);
        sink->set_pattern("%l|%v");
        auto logger = std::make_shared<spdlog::logger>("capture", sink);
        logger->set_level(spdlog::level::info);
        spdlog::set_default_logger(logger);
    }
    ~LogCapture() { spdlog::set_default_logger(previous_); }
    LogCapture(const LogCapture&) = delete;
    LogCapture& operator=(const LogCapture&) = delete;

    // Lines logged at `level` ("warning", "info").
    std::vector<std::string> lines(const std::string& level) const {
        std::vector<std::string> out;
        std::istringstream in(stream_.str());
        for (std::string line; std::getline(in, line);) {
            if (line.rfind(level + "|", 0) == 0) {
                out.push_back(line.substr(level.size() + 1));
            }
        }
        return out;
    }

private:
    std::shared_ptr<spdlog::logger> previous_;
    std::ostringstream stream_;
};

inline std::string base64(const std::vector<uint8_t>& data) {
    static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < data.size(); i += 3) {
        const uint32_t n = (uint32_t(data[i]) << 16) | (i + 1 < data.size() ? uint32_t(data[i + 1]) << 8 : 0u) |
                           (i + 2 < data.size() ? uint32_t(data[i + 2]) : 0u);
        out += kAlphabet[(n >> 18) & 63];
        out += kAlphabet[(n >> 12) & 63];
        out += i + 1 < data.size() ? kAlphabet[(n >> 6) & 63] : '=';
        out += i + 2 < data.size() ? kAlphabet[n & 63] : '=';
    }
    return out;
}

// Builds a glTF document with one embedded buffer, accessor by accessor.
class GltfFixture {
public:
    GltfFixture() {
        doc = {{"asset", {{"version", "2.0"}}}, {"accessors", Json::array()}, {"bufferViews", Json::array()}};
    }

    // Appends raw values as an accessor (tightly packed, own bufferView).
    template <typename T>
    int accessor(const std::vector<T>& values, int componentType, const char* type, size_t components) {
        const size_t offset = bin.size();
        bin.resize(offset + values.size() * sizeof(T));
        std::memcpy(bin.data() + offset, values.data(), values.size() * sizeof(T));
        bin.resize((bin.size() + 3) & ~size_t(3));
        doc["bufferViews"].push_back(
            {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", values.size() * sizeof(T)}});
        doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1},
                                    {"componentType", componentType},
                                    {"count", values.size() / components},
                                    {"type", type}});
        return int(doc["accessors"].size() - 1);
    }

    int floats(const std::vector<float>& v, const char* type, size_t components) {
        return accessor(v, 5126, type, components);
    }

    // The document with the buffer as a base64 data URI.
    std::string text() const {
        Json out = doc;
        out["buffers"] = {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}};
        return out.dump(1);
    }

    Json doc;
    std::vector<uint8_t> bin;
};

} // namespace glint::test
