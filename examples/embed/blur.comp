#version 460
// The engine's own pass: a 3x3 binomial blur of the composited RGBA8 image.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba8) uniform readonly image2D source;
layout(binding = 1, rgba8) uniform writeonly image2D target;

void main() {
    const ivec2 size = imageSize(source);
    const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, size))) return;
    vec4 sum = vec4(0.0);
    for (int y = -1; y <= 1; ++y) {
        for (int x = -1; x <= 1; ++x) {
            const float w = float((2 - abs(x)) * (2 - abs(y)));  // 1 2 1 / 2 4 2 / 1 2 1
            sum += w * imageLoad(source, clamp(p + ivec2(x, y), ivec2(0), size - 1));
        }
    }
    imageStore(target, p, sum / 16.0);
}
