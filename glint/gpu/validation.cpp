#include "glint/gpu/validation.h"

#include <sstream>

namespace glint::gpu {


namespace {
// See ValidationLog in validation.h.
bool isTimelineRaceFalsePositive(const ValidationMessage& m) {
    return m.id.rfind("SYNC-HAZARD-", 0) == 0 && m.id.find("-RACING-") != std::string::npos &&
           m.text.find("vkQueueSubmit") != std::string::npos;
}
} // namespace

void ValidationLog::add(ValidationMessage message) {
    std::lock_guard lock(mutex_);
    if (isTimelineRaceFalsePositive(message)) {
        ++setAside_;
        return;
    }
    messages_.push_back(std::move(message));
}

size_t ValidationLog::setAside() const {
    std::lock_guard lock(mutex_);
    return setAside_;
}

std::vector<ValidationMessage> ValidationLog::messages() const {
    std::lock_guard lock(mutex_);
    return messages_;
}

size_t ValidationLog::count() const {
    std::lock_guard lock(mutex_);
    return messages_.size();
}

size_t ValidationLog::countMatching(std::string_view idSubstring) const {
    std::lock_guard lock(mutex_);
    size_t n = 0;
    for (const auto& m : messages_) {
        if (m.id.find(idSubstring) != std::string::npos) {
            ++n;
        }
    }
    return n;
}

void ValidationLog::clear() {
    std::lock_guard lock(mutex_);
    messages_.clear();
}

std::string ValidationLog::summary() const {
    std::lock_guard lock(mutex_);
    std::ostringstream out;
    out << messages_.size() << " validation message(s)";
    for (const auto& m : messages_) {
        out << "\n  [" << m.id << "] " << m.text;
    }
    return out.str();
}

} // namespace glint::gpu
