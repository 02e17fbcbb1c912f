#version 460
// Smoke-test kernel: out[i] = i * scale + offset. Used by the foundation GPU test.
layout(local_size_x = 64) in;
layout(set = 0, binding = 0) buffer Out { float values[]; };
layout(push_constant) uniform Push { float scale; float offset; uint count; };
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < count) values[i] = float(i) * scale + offset;
}
