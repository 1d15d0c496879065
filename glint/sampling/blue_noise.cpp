#include "glint/sampling/blue_noise.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>

namespace glint::sampling {

namespace {

constexpr uint32_t kNone = UINT32_MAX;

// A tournament tree over the texels: each node holds the best eligible
// texel below it (least energy for voids, most for clusters; ties to the
// lower index, so the result is deterministic), kNone where none is.
class Tournament {
public:
    Tournament(const std::vector<float>& energy, bool most) : energy_(energy), most_(most) {
        leaves_ = uint32_t(energy.size());
        node_.assign(2 * size_t(leaves_), kNone);
    }

    // Rebuilds from scratch with the texels `eligible` says.
    void build(const std::vector<uint8_t>& set, bool eligibleWhenSet) {
        for (uint32_t i = 0; i < leaves_; ++i) node_[leaves_ + i] = (set[i] != 0) == eligibleWhenSet ? i : kNone;
        for (uint32_t n = leaves_ - 1; n >= 1; --n) node_[n] = pick(node_[2 * n], node_[2 * n + 1]);
    }
    void setEligible(uint32_t texel, bool eligible) {
        node_[leaves_ + texel] = eligible ? texel : kNone;
        fix(texel);
    }
    // The texel's energy changed: its ancestors choose again.
    void fix(uint32_t texel) {
        for (uint32_t n = (leaves_ + texel) >> 1; n >= 1; n >>= 1) {
            const uint32_t best = pick(node_[2 * n], node_[2 * n + 1]);
            if (node_[n] == best && best != texel) break;  // nothing above can change
            node_[n] = best;
        }
    }
    bool eligible(uint32_t texel) const { return node_[leaves_ + texel] != kNone; }
    uint32_t best() const { return node_[1]; }

private:
    uint32_t pick(uint32_t a, uint32_t b) const {
        if (a == kNone) return b;
        if (b == kNone) return a;
        const float ea = energy_[a], eb = energy_[b];
        if (ea == eb) return std::min(a, b);
        return (most_ ? ea > eb : ea < eb) ? a : b;
    }

    const std::vector<float>& energy_;
    bool most_;
    uint32_t leaves_ = 0;
    std::vector<uint32_t> node_;
};

// The volume's energy field and set texels, with the STBN kernel.
class Field {
public:
    Field(BlueNoiseSize size, float sigma) : size_(size), energy(size.texels(), 0.0f), set(size.texels(), 0) {
        const float twoSigma2 = 2.0f * sigma * sigma;
        // Out to 3.5 sigma (weight 0.002), and never so far that the
        // toroidal window meets itself.
        radius_ = std::min<int>({int(std::ceil(3.5f * sigma)), int(size.width - 1) / 2, int(size.height - 1) / 2});
        for (int dy = -radius_; dy <= radius_; ++dy) {
            for (int dx = -radius_; dx <= radius_; ++dx) {
                spatial_.push_back(std::exp(-float(dx * dx + dy * dy) / twoSigma2));
            }
        }
        for (uint32_t dt = 0; dt < size.depth; ++dt) {
            const float d = float(std::min(dt, size.depth - dt));
            temporal_.push_back(std::exp(-d * d / twoSigma2));
        }
    }

    // Adds (sign 1) or removes (-1) texel's energy; `changed(t)` for every
    // texel whose energy moved.
    template <class Changed> void splat(uint32_t texel, float sign, Changed&& changed) {
        const uint32_t w = size_.width, h = size_.height, d = size_.depth;
        const uint32_t x = texel % w, y = texel / w % h, t = texel / (w * h);
        // Its slice (itself included).
        size_t k = 0;
        for (int dy = -radius_; dy <= radius_; ++dy) {
            const uint32_t yy = (y + uint32_t(dy + int(h))) % h;
            for (int dx = -radius_; dx <= radius_; ++dx, ++k) {
                const uint32_t xx = (x + uint32_t(dx + int(w))) % w;
                const uint32_t q = (t * h + yy) * w + xx;
                energy[q] += sign * spatial_[k];
                changed(q);
            }
        }
        // Its column, the other frames.
        for (uint32_t dt = 1; dt < d; ++dt) {
            const uint32_t q = (((t + dt) % d) * h + y) * w + x;
            energy[q] += sign * temporal_[dt];
            changed(q);
        }
    }

    BlueNoiseSize size_;
    std::vector<float> energy;
    std::vector<uint8_t> set;

private:
    int radius_ = 0;
    std::vector<float> spatial_;
    std::vector<float> temporal_;
};

void checkSize(BlueNoiseSize size) {
    if (size.width < 4 || size.height < 4 || size.depth < 4 || !std::has_single_bit(size.texels()) ||
        size.texels() > (uint64_t(1) << 26)) {
        throw std::invalid_argument("blue noise: " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                                    "x" + std::to_string(size.depth) +
                                    " must have sides of at least 4 and a power-of-two texel count up to 2^26");
    }
}

constexpr std::array<char, 4> kMagic = {'G', 'L', 'B', 'N'};
constexpr uint32_t kVersion = 1;

} // namespace

std::vector<uint32_t> spatiotemporalBlueNoise(BlueNoiseSize size, uint64_t seed, float sigma) {
    checkSize(size);
    if (!(sigma > 0.5f && sigma < 8.0f)) throw std::invalid_argument("blue noise: sigma must be in (0.5, 8)");
    const uint32_t n = uint32_t(size.texels());
    Field field(size, sigma);
    Tournament voids(field.energy, false);    // unset texels, least energy first
    Tournament clusters(field.energy, true);  // set texels, most energy first
    const auto place = [&](uint32_t texel, bool on, bool trackVoids, bool trackClusters) {
        field.set[texel] = on ? 1 : 0;
        if (trackVoids) voids.setEligible(texel, !on);
        if (trackClusters) clusters.setEligible(texel, on);
        field.splat(texel, on ? 1.0f : -1.0f, [&](uint32_t q) {
            if (trackVoids && voids.eligible(q)) voids.fix(q);
            if (trackClusters && clusters.eligible(q)) clusters.fix(q);
        });
    };

    // The initial pattern: a tenth of the texels at random, then moved one
    // at a time from the tightest cluster to the largest void until the
    // texel removed is the one the void takes back.
    std::mt19937_64 random(seed);
    const uint32_t initial = std::max(1u, n / 10);
    std::vector<uint32_t> order(n);
    for (uint32_t i = 0; i < n; ++i) order[i] = i;
    for (uint32_t i = 0; i < initial; ++i) {
        std::swap(order[i], order[i + uint32_t(random() % (n - i))]);
        place(order[i], true, false, false);
    }
    voids.build(field.set, false);
    clusters.build(field.set, true);
    for (uint32_t iteration = 0; iteration < n; ++iteration) {
        const uint32_t cluster = clusters.best();
        place(cluster, false, true, true);
        const uint32_t gap = voids.best();
        place(gap, true, true, true);
        if (gap == cluster) break;
    }
    const std::vector<uint8_t> initialSet = field.set;
    const std::vector<float> initialEnergy = field.energy;

    // Ranks of the initial texels: the tightest cluster goes last.
    std::vector<uint32_t> rank(n, 0);
    for (uint32_t count = initial; count > 0; --count) {
        const uint32_t cluster = clusters.best();
        place(cluster, false, false, true);
        rank[cluster] = count - 1;
    }
    // Every other texel: the largest void comes next. (Past half full,
    // Ulichney's "tightest cluster of the minority zeros" is the same
    // texel: with a kernel the same around every texel, a zero's energy
    // from the zeros is a constant less its energy from the ones.)
    field.set = initialSet;
    field.energy = initialEnergy;
    voids.build(field.set, false);
    for (uint32_t count = initial; count < n; ++count) {
        const uint32_t gap = voids.best();
        place(gap, true, true, false);
        rank[gap] = count;
    }
    return rank;
}

BlueNoiseTexture makeBlueNoiseTexture(BlueNoiseSize size, uint32_t channels, uint64_t seed) {
    checkSize(size);
    if (channels == 0 || channels > 4) throw std::invalid_argument("blue noise: 1 to 4 channels");
    BlueNoiseTexture texture;
    texture.size = size;
    texture.channels = channels;
    const uint64_t n = size.texels();
    texture.values.resize(n * channels);
    // One thread per channel: the runs are independent.
    std::vector<std::vector<uint32_t>> ranks(channels);
    std::vector<std::thread> threads;
    for (uint32_t c = 0; c < channels; ++c) {
        threads.emplace_back([&, c] { ranks[c] = spatiotemporalBlueNoise(size, seed + c); });
    }
    for (std::thread& t : threads) t.join();
    for (uint32_t c = 0; c < channels; ++c) {
        for (uint64_t i = 0; i < n; ++i) {
            texture.values[i * channels + c] = uint16_t((uint64_t(ranks[c][i]) << 16) / n);
        }
    }
    return texture;
}

std::vector<uint32_t> blueNoiseWords(const BlueNoiseTexture& texture) {
    const uint32_t wordsPerTexel = (texture.channels + 1) / 2;
    std::vector<uint32_t> words(texture.size.texels() * wordsPerTexel, 0);
    for (uint64_t texel = 0; texel < texture.size.texels(); ++texel) {
        for (uint32_t c = 0; c < texture.channels; ++c) {
            words[texel * wordsPerTexel + c / 2] |= uint32_t(texture.values[texel * texture.channels + c]) << (16 * (c % 2));
        }
    }
    return words;
}

void writeBlueNoise(const std::filesystem::path& file, const BlueNoiseTexture& texture) {
    if (texture.values.size() != texture.size.texels() * texture.channels) {
        throw std::runtime_error(file.string() + ": blue noise of inconsistent size");
    }
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    const std::array<uint32_t, 5> header = {kVersion, texture.size.width, texture.size.height, texture.size.depth,
                                            texture.channels};
    out.write(kMagic.data(), kMagic.size());
    out.write(reinterpret_cast<const char*>(header.data()), sizeof(header));
    out.write(reinterpret_cast<const char*>(texture.values.data()),
              std::streamsize(texture.values.size() * sizeof(uint16_t)));
    if (!out) throw std::runtime_error(file.string() + ": cannot write the blue noise");
}

BlueNoiseTexture readBlueNoise(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw std::runtime_error(file.string() + ": cannot open the blue noise (build the project first)");
    std::array<char, 4> magic{};
    std::array<uint32_t, 5> header{};
    in.read(magic.data(), magic.size());
    in.read(reinterpret_cast<char*>(header.data()), sizeof(header));
    if (!in || magic != kMagic) throw std::runtime_error(file.string() + ": not a Glint blue noise file");
    if (header[0] != kVersion) {
        throw std::runtime_error(file.string() + ": blue noise version " + std::to_string(header[0]) + ", expected " +
                                 std::to_string(kVersion));
    }
    BlueNoiseTexture texture;
    texture.size = {header[1], header[2], header[3]};
    texture.channels = header[4];
    try {
        checkSize(texture.size);
    } catch (const std::invalid_argument& e) {
        throw std::runtime_error(file.string() + ": " + e.what());
    }
    if (texture.channels == 0 || texture.channels > 4) {
        throw std::runtime_error(file.string() + ": " + std::to_string(texture.channels) + " channels (1 to 4)");
    }
    texture.values.resize(texture.size.texels() * texture.channels);
    in.read(reinterpret_cast<char*>(texture.values.data()), std::streamsize(texture.values.size() * sizeof(uint16_t)));
    if (!in) throw std::runtime_error(file.string() + ": truncated blue noise");
    in.peek();
    if (!in.eof()) throw std::runtime_error(file.string() + ": trailing bytes after the blue noise");
    return texture;
}

} // namespace glint::sampling
