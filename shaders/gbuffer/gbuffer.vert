#version 460
// G-buffer geometry: pulls the vertex from the scene's one vertex buffer
// (gl_VertexIndex includes the draw's vertex offset), skins it with this and
// last frame's joint palettes, and places it with this and last frame's
// instance transform (gl_InstanceIndex: each draw's firstInstance is its
// instance), so motion covers camera, rigid, skinned and morph movement (a
// morphing instance's last-frame copy, previousVertexDelta).
#extension GL_GOOGLE_include_directive : require

#include "gbuffer_common.glsl"

layout(location = 0) out vec3 outWorldPosition;
layout(location = 1) out vec3 outNormal;
layout(location = 2) out vec4 outAlbedo;     // rgb, a = coverage
layout(location = 3) out vec3 outMaterial;  // roughness, metallic, reflectance
layout(location = 4) out vec4 outClip;      // unjittered, this frame
layout(location = 5) out vec4 outPreviousClip;
layout(location = 6) out vec4 outTangent;  // world xyz, w = bitangent sign
layout(location = 7) out vec4 outUv;       // uv0, uv1
layout(location = 8) out vec3 outEmissive; // glTF units, without the per-pixel texture

void main() {
    const GBufferVertex v = vertices[gl_VertexIndex];
    const GBufferInstance inst = instances[gl_InstanceIndex];
    vec3 position = v.position;
    // Last frame's object-space position: a morph moves the vertex itself.
    const vec3 previousBase =
        inst.previousVertexDelta != 0u ? vertices[gl_VertexIndex + int(inst.previousVertexDelta)].position : v.position;
    vec3 previousPosition = previousBase;
    vec3 normal = v.normal;
    vec3 tangent = v.tangent.xyz;
    if (inst.jointCount > 0u) {
        const mat4 skin = skinMatrix(v, inst, false);
        position = (skin * vec4(v.position, 1.0)).xyz;
        previousPosition = (skinMatrix(v, inst, true) * vec4(previousBase, 1.0)).xyz;
        // Rigs carry no non-uniform scale: the upper 3x3 transforms normals.
        normal = mat3(skin) * v.normal;
        tangent = mat3(skin) * tangent;
    }
    const vec4 world = inst.transform * vec4(position, 1.0);
    const vec4 previousWorld = inst.previousTransform * vec4(previousPosition, 1.0);
    // Instance transforms may scale non-uniformly: normals go through the
    // inverse transpose.
    outNormal = transpose(inverse(mat3(inst.transform))) * normal;
    // Tangents lie in the surface: they follow the transform itself. A
    // mirroring transform flips the bitangent's sign (mesh_tools.cpp,
    // transformGeometry, does the same on the CPU).
    const mat3 linear = mat3(inst.transform);
    outTangent = vec4(linear * tangent, determinant(linear) < 0.0 ? -v.tangent.w : v.tangent.w);
    outUv = vec4(v.uv0, v.uv1);
    outWorldPosition = world.xyz;
    outAlbedo = vec4(v.albedo, v.alpha);
    outEmissive = v.emissive;
    outMaterial = vec3(v.roughness, v.metallic, v.reflectance);
    outClip = frame.viewProjection * world;
    outPreviousClip = frame.previousViewProjection * previousWorld;
    gl_Position = frame.jitteredViewProjection * world;
}
