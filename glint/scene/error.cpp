#include "glint/scene/error.h"

namespace glint::scene {

namespace {
std::string formatMessage(const std::string& file, const std::string& element, const std::string& detail) {
    std::string message = file.empty() ? std::string("<scene>") : file;
    message += ": ";
    if (!element.empty()) {
        message += element;
        message += ": ";
    }
    message += detail;
    return message;
}
} // namespace

SceneError::SceneError(std::string file, std::string element, const std::string& detail)
    : std::runtime_error(formatMessage(file, element, detail)), file_(std::move(file)), element_(std::move(element)) {}

} // namespace glint::scene
