#version 460
// The sky behind the G-buffer: one triangle covering the screen at depth 0
// (the reversed-Z far plane), drawn after the geometry without depth writes,
// so it fills only the pixels no geometry covered.
void main() {
    const vec2 uv = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
