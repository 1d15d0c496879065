// Definitions shared by GLSL and C++. Included by both: in C++ the GLSL
// vector types map onto glm types with the same scalar layout, so structs
// declared between GLINT_BEGIN and GLINT_END have one definition.
#ifndef GLINT_SHARED_H
#define GLINT_SHARED_H

#ifdef __cplusplus
#include <glm/glm.hpp>
#include <cstdint>
namespace glint::shader {
using uint = uint32_t;
using vec2 = glm::vec2;
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using uvec2 = glm::uvec2;
using uvec3 = glm::uvec3;
using uvec4 = glm::uvec4;
using mat4 = glm::mat4;
} // namespace glint::shader
#define GLINT_BEGIN namespace glint::shader {
#define GLINT_END }
#define GLINT_CONST inline constexpr
#else
#define GLINT_BEGIN
#define GLINT_END
#define GLINT_CONST const
#endif

#endif
