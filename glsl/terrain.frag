#version 460
// Section 8.3: terrain coloured by height (dirt, grass, rock, snow with blended transitions), rock on steep
// slopes, lit by the sun; rivers too thin for the mesh painted from the signed distance and width (8.4). The
// water pass shades water by depth with a specular highlight.
#include "terrain_common.glsl"

layout(constant_id = 0) const uint WATER_PASS = 0;

layout(location = 0) in vec3 fPosition;
layout(location = 1) in vec3 fNormal;
layout(location = 2) in vec4 fRiver;
layout(location = 3) flat in int fRiverWater;
layout(location = 4) flat in float fLevel;
layout(location = 5) in vec3 fDirection;
layout(location = 9) flat in float fSpacing;

layout(location = 0) out vec4 outColor;

// Cheap value noise for procedural texture detail (no external assets).
float hash(vec3 p) {
    p = fract(p * 0.3183099 + 0.1);
    p *= 17.0;
    return fract(p.x * p.y * p.z * (p.x + p.y + p.z));
}

float noise(vec3 x) {
    vec3 i = floor(x);
    vec3 f = fract(x);
    f = f * f * (3.0 - 2.0 * f);
    return mix(mix(mix(hash(i), hash(i + vec3(1, 0, 0)), f.x), mix(hash(i + vec3(0, 1, 0)), hash(i + vec3(1, 1, 0)), f.x), f.y),
               mix(mix(hash(i + vec3(0, 0, 1)), hash(i + vec3(1, 0, 1)), f.x), mix(hash(i + vec3(0, 1, 1)), hash(i + vec3(1, 1, 1)), f.x), f.y), f.z);
}

const vec3 DIRT = vec3(0.45, 0.36, 0.25);
const vec3 SAND = vec3(0.76, 0.70, 0.50);
const vec3 GRASS = vec3(0.26, 0.45, 0.18);
const vec3 ROCK = vec3(0.42, 0.40, 0.38);
const vec3 SNOW = vec3(0.93, 0.94, 0.97);
const vec3 WATER_SHALLOW = vec3(0.12, 0.42, 0.55);
const vec3 WATER_DEEP = vec3(0.02, 0.10, 0.28);

// Fig. 8.2: weights of the textures by height, with linear transitions; heights in units of frame.extra.z, so
// that the bands keep their place relative to the mountains on any planet.
vec3 terrainColour(float height, float slope, vec3 detail) {
    float sea = frame.sun.w;
    float h = (height - sea) / frame.extra.z;
    vec3 c = mix(SAND, DIRT, smoothstep(0.0, 0.6, h));
    c = mix(c, GRASS, smoothstep(0.4, 1.4, h));
    c = mix(c, ROCK, smoothstep(6.0, 9.0, h));
    c = mix(c, SNOW, smoothstep(12.0, 14.5, h));
    // Steep slopes show rock (8.3).
    c = mix(c, ROCK * 0.9, smoothstep(0.55, 0.8, slope));
    if (h < 0.0) c = mix(SAND, DIRT * 0.6, clamp(-h / 3.0, 0.0, 1.0));
    return c * (0.85 + 0.3 * detail);
}

vec3 levelColour(float level) {
    vec3 palette[8] = vec3[](vec3(0.9, 0.2, 0.2), vec3(0.9, 0.6, 0.1), vec3(0.9, 0.9, 0.2), vec3(0.3, 0.8, 0.3),
                             vec3(0.2, 0.8, 0.8), vec3(0.2, 0.4, 0.9), vec3(0.6, 0.3, 0.9), vec3(0.9, 0.3, 0.7));
    return palette[int(level) % 8];
}

void main() {
    vec3 sun = normalize(frame.sun.xyz);
    vec3 up = normalize(fDirection);
    vec3 view = normalize(-fPosition);
    if (WATER_PASS == 1) {
        // River water covers the basin only: a triangle reaching past the banks is cut at the river's width.
        if (fRiverWater == 1 && abs(fRiver.z) > fRiver.w) discard;
        float depth = max(fRiver.y - fRiver.x, 0.0);
        vec3 colour = mix(WATER_SHALLOW, WATER_DEEP, clamp(depth / (4.0 * frame.extra.z), 0.0, 1.0));
        float diffuse = max(dot(up, sun), 0.0);
        vec3 reflected = reflect(-sun, up);
        float specular = pow(max(dot(reflected, view), 0.0), 80.0) * step(0.0, dot(up, sun));
        float fresnel = 0.02 + 0.98 * pow(1.0 - max(dot(up, view), 0.0), 5.0);
        colour = colour * (0.25 + 0.75 * diffuse) + vec3(1.0, 0.95, 0.85) * specular * 0.8 + vec3(0.5, 0.6, 0.7) * fresnel * 0.3;
        float alpha = clamp(0.55 + depth / frame.extra.z * 0.3, 0.55, 0.92);
        outColor = vec4(colour, alpha);
        return;
    }
    vec3 normal = normalize(fNormal);
    float slope = 1.0 - clamp(dot(normal, up), 0.0, 1.0);
    // One octave of detail noise about a world unit across (two octaves cost lavapipe 15 ms a frame at 720p).
    float detail = noise(fDirection * frame.planet.x);
    vec3 albedo = terrainColour(fRiver.x, slope * 3.0, vec3(detail));
    if (uint(frame.planet.w) == 1) albedo = mix(albedo, levelColour(fLevel), 0.6);
    // Section 8.4: paint a river the mesh is too coarse to carve (vertices not closer than half its width, the
    // thesis's rule, in `auto`), from the signed distance and width.
    uint mode = uint(frame.planet.z);
    bool paint = mode == WATER_PAINTED || (mode == WATER_AUTO && fSpacing >= fRiver.w);
    if (paint && fRiver.w > 0.0) {
        float edge = fwidth(fRiver.z) + 1e-4;
        float inside = 1.0 - smoothstep(fRiver.w - edge, fRiver.w + edge, abs(fRiver.z));
        vec3 paint = uint(frame.planet.w) == 2 ? vec3(0.9, 0.1, 0.1) : WATER_SHALLOW;
        albedo = mix(albedo, paint, inside);
    }
    float diffuse = max(dot(normal, sun), 0.0);
    float ambient = 0.18 + 0.12 * max(dot(up, sun) + 0.3, 0.0);
    vec3 colour = albedo * (ambient + 0.85 * diffuse);
    // Aerial perspective: distant terrain fades towards the sky colour.
    float distance = length(fPosition);
    colour = mix(colour, vec3(0.55, 0.65, 0.8), clamp(distance / (frame.planet.x * 6.0), 0.0, 0.35));
    outColor = vec4(colour, 1.0);
}
