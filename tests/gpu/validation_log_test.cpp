// What the validation log keeps and what it sets aside; no GPU needed.
#include "glint/gpu/validation.h"

#include <doctest/doctest.h>

using glint::gpu::ValidationLog;

namespace {
constexpr auto kError = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
}

TEST_CASE("validation log keeps every message but submit-time cross-queue races") {
    ValidationLog log;
    log.add({kError, "SYNC-HAZARD-READ-RACING-WRITE", "vkQueueSubmit2: Hazard READ_RACING_WRITE for entry 0"});
    CHECK(log.count() == 0);
    CHECK(log.setAside() == 1);
    // A race inside one command buffer is no timeline artefact: kept.
    log.add({kError, "SYNC-HAZARD-WRITE-RACING-WRITE", "vkCmdDispatch: Hazard WRITE_RACING_WRITE"});
    // Ordinary hazards at submission are kept too.
    log.add({kError, "SYNC-HAZARD-READ-AFTER-WRITE", "vkQueueSubmit2: Hazard READ_AFTER_WRITE for entry 0"});
    log.add({kError, "VUID-vkCmdDispatch-None-02691", "anything"});
    CHECK(log.count() == 3);
    CHECK(log.countMatching("SYNC-HAZARD") == 2);
    CHECK(log.summary().find("VUID-vkCmdDispatch-None-02691") != std::string::npos);
    log.clear();
    CHECK(log.count() == 0);
}
