#pragma once
// GPU objects a renderer replaced while frames in flight may still read
// them: kept until the executor has waited for every frame that could.
// Frames are counted by the renderer's own per-frame calls (its prepare()).

#include <algorithm>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace glint::passes {

class RetiredObjects {
public:
    explicit RetiredObjects(uint32_t framesInFlight) : framesInFlight_(framesInFlight) {}

    // Keeps `object` while frames up to `lastUse` may use it.
    template <class T> void keep(T&& object, uint64_t lastUse) {
        keepShared(std::make_shared<std::decay_t<T>>(std::forward<T>(object)), lastUse);
    }
    void keepShared(std::shared_ptr<void> object, uint64_t lastUse) { items_.push_back({lastUse, std::move(object)}); }

    // Called while frame `frame` is prepared. Before the executor runs frame
    // N it has waited for frame N - framesInFlight; the preparation of frame
    // N comes before that wait, so frame N - 1 - framesInFlight is the
    // newest one known to be finished.
    void release(uint64_t frame) {
        std::erase_if(items_, [&](const Item& i) { return i.lastUse + framesInFlight_ < frame; });
    }

private:
    struct Item {
        uint64_t lastUse = 0;  // the last frame whose commands may touch it
        std::shared_ptr<void> object;
    };
    uint32_t framesInFlight_;
    std::vector<Item> items_;
};

} // namespace glint::passes
