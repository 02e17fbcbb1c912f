#version 460
// Section 8.3: terrain coloured by height (dirt, grass, rock, snow with blended transitions), rock on steep
// slopes, lit by the sun; rivers too thin for the mesh painted from the signed distance and width (8.4). The
// water pass shades water by depth with a specular highlight.
#include "terrain_common.glsl"
#include "atmosphere.glsl"

layout(constant_id = 0) const uint WATER_PASS = 0;
// Beyond the thesis: 1 in the pipeline that draws the patches a lake of the lake map reaches (docs/rendering.md,
// "Lakes from afar"); 0 elsewhere, where the lake map's code is compiled out (its mere presence cost lavapipe 7 to
// 11 % of the terrain pass).
layout(constant_id = 1) const uint LAKE_MAP = 0;

#include "terrain_interface.glsl"

layout(location = 0) out vec4 outColor;

const vec3 DIRT = vec3(0.45, 0.36, 0.25);
const vec3 SAND = vec3(0.76, 0.70, 0.50);
const vec3 GRASS = vec3(0.26, 0.45, 0.18);
const vec3 ROCK = vec3(0.42, 0.40, 0.38);
const vec3 SNOW = vec3(0.93, 0.94, 0.97);
const vec3 WATER_SHALLOW = vec3(0.12, 0.42, 0.55);
const vec3 WATER_DEEP = vec3(0.02, 0.10, 0.28);

// Beyond the thesis (terrain close up): detail below the vertex spacing, three octaves of value noise from one
// world unit down to 1/16, each fading out while its cells shrink from about three pixels to one and a half
// (smaller cells alias: they sparkle as the camera moves), so the ground keeps detail at a few units (metres on
// config/earth.xml). Where even the unit octave is that small (Earth's ground from tens of metres up and higher),
// coarser octaves of 4, 16 and 64 units take over, each fading out again once its cells pass 128 pixels: without
// them a planet in metres showed one flat colour from a kilometre up. A view that resolves the unit octave looks
// as it did. In [0, 1], 0.5 where nothing shows.
// Coordinates: fDetail, the world position modulo a multiple of GROUND_DETAIL_PERIOD (precise near the camera at any
// planet size).
float groundDetail() {
    // About 1.4 to 2 pixels' size on the surface.
    float footprint = length(fwidth(fDetail));
    float sum = 0.0;
    float amplitude = 1.0;
    float size = 1.0;
    for (int k = 0; k < 3; ++k, amplitude *= 0.6, size *= 0.25) {
        float fade = 1.0 - smoothBand(0.35, 0.7, footprint / size);
        if (fade <= 0.0) break;
        sum += amplitude * fade * (periodicNoise(fDetail / size, GROUND_DETAIL_PERIOD / size) - 0.5);
    }
    float coarse = smoothBand(0.35, 0.7, footprint);
    size = 4.0;
    for (int k = 0; k < 3 && coarse > 0.0; ++k, size *= 4.0) {
        float pixels = size / max(footprint, 1e-6);
        float fade = coarse * (1.0 - smoothBand(0.35, 0.7, 1.0 / pixels)) * (1.0 - smoothBand(128.0, 1024.0, pixels));
        // Only the octaves that show (from orbit, most pixels show one or two of the three).
        if (fade > 0.0) sum += 0.4 * fade * (periodicNoise(fDetail / size, GROUND_DETAIL_PERIOD / size) - 0.5);
    }
    return clamp(0.5 + sum / 1.4, 0.0, 1.0);
}

// Beyond the thesis (docs/rendering.md, "Climate"): what the climate makes of a place, from its latitude and the
// moisture field its vertices computed (noise.glsl, moistureAt).
const vec3 FOREST = vec3(0.13, 0.27, 0.10);
const vec3 STEPPE = vec3(0.53, 0.48, 0.30);
const vec3 DESERT = vec3(0.80, 0.67, 0.46);
const vec3 TUNDRA = vec3(0.41, 0.39, 0.31);
const vec3 SEA_ICE = vec3(0.86, 0.90, 0.95);
// Snow and land ice, darker than Fig. 8.2's snow so that sunlit slopes stay below white and the relief shows.
const vec3 ICE = vec3(0.78, 0.81, 0.86);
// Glacier ice where a river runs above the snow line: bluer than the snow, so that its course still shows.
const vec3 GLACIER = vec3(0.62, 0.72, 0.82);

struct Climate {
    float latitude;  // degrees from the equator, either side
    float moisture;  // the large-scale noise field, in [0, 1]
    float aridity;   // 0 wet (rain forest) to 1 (desert)
    float snowLine;  // in colour-band units above sea level
};

Climate climateAt(vec3 up, float moisture) {
    Climate c;
    c.latitude = degrees(asin(min(abs(up.y), 1.0)));
    c.moisture = moisture;
    // The subtropical dry belts under the Hadley cells' descending air, centred near 26 degrees (the Sahara,
    // Arabia, Australia, the Kalahari, the Atacama), between the wet tropics and the mid-latitudes' storm tracks.
    float fromBelt = (c.latitude - 26.0) * (1.0 / 11.0);
    float belt = exp(-fromBelt * fromBelt);
    c.aridity = clamp(belt * 0.9 + (c.moisture - 0.5) * 2.6, 0.0, 1.0);
    // The snow line: about 5 km (10 units of 500 m on Earth) in the tropics, 3.8 km at 45 degrees, 1.5 km at 60,
    // down to sea level past 72 (Greenland's and Antarctica's ice); up to 1.25 km higher where the air is dry (the
    // Andes' dry belt, Tibet), as Earth's equilibrium lines lie.
    c.snowLine = 11.0 * (1.0 - smoothBand(28.0, 80.0, c.latitude)) + 2.5 * c.aridity - 0.6;
    return c;
}

// Beyond the thesis: Fig. 8.2's bands placed by climate. Vegetation by aridity (forest, grassland, steppe,
// desert); tundra below the snow line's lowest few units, bare rock in the mountains just under it, snow and ice
// above it; sand on the beaches only.
vec3 climateColour(float h, float shore, Climate c) {
    vec3 vegetation = mix(FOREST, GRASS, smoothBand(0.15, 0.4, c.aridity));
    vegetation = mix(vegetation, STEPPE, smoothBand(0.45, 0.62, c.aridity));
    vegetation = mix(vegetation, DESERT, smoothBand(0.65, 0.85, c.aridity));
    float below = c.snowLine - h;
    vec3 colour = mix(vegetation, TUNDRA, 1.0 - smoothBand(1.0, 3.5, below));
    colour = mix(colour, ROCK, (1.0 - smoothBand(0.2, 1.5, below)) * smoothBand(2.0, 5.0, h));
    colour = mix(colour, ICE, smoothBand(-0.8, 0.8, -below));
    return mix(SAND, colour, smoothBand(0.0, 0.03, shore));
}

// Beyond the thesis ("Climate"): the light on ice lying flat at `up` (as the terrain's: ambient and sunlight).
vec3 iceLight(vec3 up, vec3 sun) {
    float light = max(dot(up, sun), 0.0);
    return (0.18 + 0.12 * max(light + 0.3, 0.0)) + 0.85 * light * fSunlight;
}

// The polar sea frozen over `water`, from about 74 degrees (the Arctic's summer ice edge lies near 75-80, its
// winter edge near 60-70; Antarctica's sea ice reaches 55-65 in winter); `detail` the ground detail (0.5 for none).
vec4 withSeaIce(vec4 water, Climate c, vec3 up, vec3 sun, float detail) {
    if (c.latitude < 55.0) return water;
    // The edge wanders by about ten degrees with the moisture field, and frays at a few hundred kilometres.
    float fray = periodicNoise(up * 40.0 + 3.0, 256.0);
    float edge = 74.0 + (c.moisture - 0.5) * 24.0 + (fray - 0.5) * 5.0;
    float ice = smoothBand(-0.8, 0.8, c.latitude - edge);
    return mix(water, vec4(SEA_ICE * (0.85 + 0.3 * detail) * iceLight(up, sun), 1.0), ice);
}

// Rivers and lakes above the snow line are ice, as the land around them (`height` the terrain's): lakes frozen
// over, rivers glaciers that keep their course. Without it they were blue lines and pools in the ice sheets.
vec4 withFreshIce(vec4 water, float height, Climate c, vec3 up, vec3 sun) {
    float frozen = smoothBand(-0.8, 0.8, (height - frame.sun.w) / frame.extra.z - c.snowLine);
    return mix(water, vec4(GLACIER * iceLight(up, sun), 1.0), frozen);
}

// Fig. 8.2: weights of the textures by height, with linear transitions; heights in units of frame.extra.z, so
// that the bands keep their place relative to the mountains on any planet, `fray` of them from the ground detail.
// With CLIMATE, the bands of `climateColour` instead.
vec3 terrainColour(float height, float fray, float slope, vec3 detail, Climate climate) {
    float sea = frame.sun.w;
    float h = (height + fray * frame.extra.z - sea) / frame.extra.z;
    vec3 c;
    if (CLIMATE == 1u) {
        c = climateColour(h, h - fray, climate);
    } else {
        c = mix(SAND, DIRT, smoothBand(0.0, 0.6, h));
        c = mix(c, GRASS, smoothBand(0.4, 1.4, h));
        c = mix(c, ROCK, smoothBand(6.0, 9.0, h));
        c = mix(c, SNOW, smoothBand(12.0, 14.5, h));
    }
    // Steep slopes show rock (8.3).
    c = mix(c, ROCK * 0.9, smoothBand(0.55, 0.8, slope));
    // Under the sea (with CLIMATE by the height itself: frayed, the coastal plains were spotted with sea floor).
    float under = CLIMATE == 1u ? h - fray : h;
    if (under < 0.0) c = mix(SAND, DIRT * 0.6, clamp(-under / 3.0, 0.0, 1.0));
    return c * (0.7 + 0.6 * detail);
}

vec3 levelColour(float level) {
    vec3 palette[8] = vec3[](vec3(0.9, 0.2, 0.2), vec3(0.9, 0.6, 0.1), vec3(0.9, 0.9, 0.2), vec3(0.3, 0.8, 0.3),
                             vec3(0.2, 0.8, 0.8), vec3(0.2, 0.4, 0.9), vec3(0.6, 0.3, 0.9), vec3(0.9, 0.3, 0.7));
    return palette[int(level + 0.5) % 8];
}

// Beyond the thesis (water that flows): ripples of two octaves of value noise, `q` in ripple sizes, carried
// along `velocity` (ripple sizes per second) and restarted every FLOW_PERIOD seconds in two phases half a period
// apart that cross-fade (flow mapping, Vlachos 2010), so that a flow varying in space never stretches them.
const float FLOW_PERIOD = 2.0;

// Value noise and its gradient from the same eight lattice values (the interpolant's derivative, Quilez):
// the ripples' normals without the finite differences' four evaluations per octave.
vec4 noiseGradient(vec3 x) {
    vec3 i = floor(x);
    vec3 f = fract(x);
    vec3 u = f * f * (3.0 - 2.0 * f);
    vec3 du = 6.0 * f * (1.0 - f);
    float corner[8];
    cornerHashes(scramble(i), scramble(i + 1.0), corner);
    float a = corner[0], b = corner[1], c = corner[2], d = corner[3];
    float e = corner[4], g = corner[5], h = corner[6], k = corner[7];
    float kx = b - a, ky = c - a, kz = e - a;
    float kxy = a - b - c + d, kyz = a - c - e + h, kzx = a - b - e + g;
    float kxyz = -a + b + c - d + e - g - h + k;
    float value = a + kx * u.x + ky * u.y + kz * u.z + kxy * u.x * u.y + kyz * u.y * u.z + kzx * u.z * u.x
                + kxyz * u.x * u.y * u.z;
    vec3 gradient = du * vec3(kx + kxy * u.y + kzx * u.z + kxyz * u.y * u.z,
                              ky + kyz * u.z + kxy * u.x + kxyz * u.z * u.x,
                              kz + kzx * u.x + kyz * u.y + kxyz * u.x * u.y);
    return vec4(gradient, value);
}

// The ripples' height field, two octaves, and its gradient (xyz) with its value (w). The fine octave, 2.3 times
// smaller, takes `fine` of its weight (it fades out sooner than the ripples as a whole, rippleSpace), and is not
// evaluated where it has faded.
vec4 ripple(vec3 q, float fine) {
    vec4 r = noiseGradient(q);
    if (fine > 0.0) {
        vec4 small = noiseGradient(q * 2.3 + 11.0);
        r += 0.5 * fine * vec4(small.xyz * 2.3, small.w);
    }
    return r;
}

// The two phases' positions and the first one's weight.
void flowPhases(vec3 q, vec3 velocity, out vec3 q0, out vec3 q1, out float w0) {
    float t = frame.extra.y / FLOW_PERIOD;
    float phase0 = fract(t);
    float phase1 = fract(t + 0.5);
    w0 = 1.0 - abs(1.0 - 2.0 * phase0);
    q0 = q - velocity * (phase0 * FLOW_PERIOD);
    q1 = q - velocity * (phase1 * FLOW_PERIOD) + vec3(0.41, 0.27, 0.63);
}

// The rippled water normal around `up` from the two phases' ripples, weighted by `strength`.
vec3 flowingNormal(vec3 up, vec4 r0, vec4 r1, float w0, float strength) {
    vec3 g = w0 * r0.xyz + (1.0 - w0) * r1.xyz;
    return normalize(up - strength * (g - up * dot(g, up)));
}

// The air between the eye and the surface: what it lets through plus what it scatters towards the eye (both per
// vertex, the latter tone-mapped there: atmosphere.glsl and terrain_vertex.glsl); without an atmosphere, a constant
// haze that grows with distance.
vec3 throughAir(vec3 colour) {
    if (!atmosphereOn()) {
        return mix(colour, vec3(0.55, 0.65, 0.8), clamp(length(fPosition) / (frame.planet.x * 6.0), 0.0, 0.35));
    }
    return colour * fTransmittance + fInscatter;
}

// The share of the foam band that the ripples leave foam in, on average (the foam's value where they are too
// small to see).
const float FOAM_COVER = 0.15;

// How deep a river looks: the painting's water, half a colour band deep (Section 8.4).
float riverLookDepth() { return 0.5 * frame.extra.z; }

// How much of the ground standing water hides: more the deeper it is.
float depthOpacity(float depth) { return clamp(0.55 + depth / frame.extra.z * 0.3, 0.55, 0.92); }

// Beyond the thesis (docs/rendering.md, "River water"): a river the mesh carves is drawn as the painting draws it,
// opaque and half a colour band deep, but for the outer part of its channel, where the bed shows through towards the
// bank. Its real depth (the basin's, a fraction of a colour band) made it pale and translucent, so a river changed
// from dark to pale as the camera came close enough for the mesh to carve it. `bankShare`: |distance| / half width.
float riverOpacity(float bankShare) { return 1.0 - 0.45 * smoothBand(0.6, 1.0, bankShare); }

// Beyond the thesis: the lit colour and opacity of water, flowing unless still (the thesis's, Section 8.4): the
// rippled normal, foam at the bank (rivers) or the shore (the sea) broken up by the moving ripples, the reflected
// sky, the sun's glint. `q`: the fragment in ripple sizes, `visible`: how much the ripples and their fine octave
// show (both from rippleSpace, in uniform control flow); `depth`: how deep the water looks (its colour);
// `opacity`: how much of the ground it hides before its foam.
vec4 waterSurface(bool river, float depth, float opacity, vec3 q, vec2 visible, vec3 up, vec3 view, vec3 sun) {
    vec3 wind = cross(up, vec3(0.0, 1.0, 0.0));
    vec3 velocity = river ? fFlow * 0.8 : wind * 0.15;
    vec3 q0, q1;
    float w0;
    flowPhases(q, velocity, q0, q1, w0);
    float edge = stillWater() ? 0.0
               : river ? smoothBand(0.7, 1.0, abs(fRiver.z) / fRiver.w)
                       : 1.0 - smoothBand(0.0, 0.25 * frame.extra.z, depth);
    // Ripples only where they show (distant water skips the noise); the foam, broken up by the ripples, fades to
    // its average cover where they are smaller than a pixel (else the banks sparkle in the distance).
    vec3 surface = up;
    float cover = FOAM_COVER;
    if (visible.x > 0.0) {
        vec4 r0 = ripple(q0, visible.y);
        vec4 r1 = ripple(q1, visible.y);
        surface = flowingNormal(up, r0, r1, w0, 0.35 * visible.x);
        cover = mix(FOAM_COVER, smoothBand(0.8, 1.2, w0 * r0.w + (1.0 - w0) * r1.w), visible.x);
    }
    float foam = edge * cover;
    vec3 colour = mix(WATER_SHALLOW, WATER_DEEP, clamp(depth / (4.0 * frame.extra.z), 0.0, 1.0));
    colour = mix(colour, vec3(0.92, 0.95, 0.97), foam * 0.85);
    vec3 diffuse = max(dot(surface, sun), 0.0) * fSunlight;
    vec3 reflected = reflect(-sun, surface);
    float specular = pow(max(dot(reflected, view), 0.0), 80.0) * step(0.0, dot(up, sun)) * (1.0 - foam);
    float fresnel = 0.02 + 0.98 * pow(1.0 - max(dot(surface, view), 0.0), 5.0);
    // The sky it reflects, from the horizon's colour to the zenith's (what makes ripples show at grazing views).
    float reflectedUp = clamp(dot(reflect(-view, surface), up), 0.0, 1.0);
    vec3 sky = mix(vec3(0.62, 0.72, 0.84), vec3(0.16, 0.28, 0.55), sqrt(reflectedUp)) * (1.0 - foam);
    colour = mix(colour * (0.25 + 0.75 * diffuse), sky, fresnel * 0.8) + vec3(1.0, 0.95, 0.85) * fSunlight * specular * 0.8;
    return vec4(colour, max(opacity, foam));
}

// The fragment in ripple sizes (rivers: the river's half width; the sea: a unit of colour band, extra.z) and how
// much ripples show (x) and their fine octave (y): each fades where its cells come near a pixel's size (the fine
// octave's, 2.3 times smaller, alone left white strokes across rivers seen from above), and still water has none.
// Takes derivatives.
// From fDetail, small near the camera: the direction times the radius in f32 put an Earth river's ripples 0.4 m
// apart, a tenth of a ripple on a narrow one, and broke them into streaks.
vec3 rippleSpace(bool river, out vec2 visible) {
    float size = river ? max(fRiver.w, 0.02) : frame.extra.z;
    vec3 q = fDetail / size;
    float footprint = length(fwidth(q));
    visible = stillWater() ? vec2(0.0)
                           : vec2(1.0) - vec2(smoothBand(0.4, 1.2, footprint), smoothBand(0.4, 1.2, 2.3 * footprint));
    return q;
}

// How fast the interpolated signed distance to the nearest river changes along the surface, per unit of length.
// A distance changes at most as fast as one moves, so where a triangle's vertices measure the same river it is
// at most sqrt(2) (a right triangle's interpolant of a 1-Lipschitz field). Where they measure different rivers, or
// one measures none (the influence distance's default) or sits beyond a river's end (the sign flips there), the
// vertices' distances differ by more than their separation and the interpolant crosses zero where no river is.
// `dz`: the distance's screen derivatives (or another interpolant's: riverSlope); `px`, `py`: the position's.
float distanceSlope(vec2 dz, vec3 px, vec3 py) {
    float a = dot(px, px), b = dot(px, py), c = dot(py, py);
    // |grad z|^2 on the triangle's plane: dz G^-1 dz with G the Gram matrix of the screen derivatives.
    float g2 = (c * dz.x * dz.x - 2.0 * b * dz.x * dz.y + a * dz.y * dz.y) / max(a * c - b * b, 1e-30);
    return sqrt(max(g2, 0.0));
}

// Beyond the thesis: the largest slope at which an interpolated distance is taken for a river's (sqrt 2 and a
// margin for the curvature of the mesh on the sphere).
const float RIVER_SLOPE_LIMIT = 1.6;
// Beyond the thesis: the smallest slope at which an interpolated distance is taken for a river's, on a triangle
// more than RIVER_FLAT_SPACING half widths across. Across one river the signed distance changes by one unit per
// unit of length; where a large triangle's vertices measured a river's end, a confluence's two branches or the far
// sides of a bend, their distances are alike, the interpolant is nearly flat and its band |distance| < half width
// spreads over the whole triangle: from orbit, angular blobs of painted water many times a river's width
// (docs/rendering.md, "Blobs of painted water"). On a triangle about as wide as the river a flat interpolant is a
// confluence's water, which stays. Half the unit slope is a bend of 120 degrees within one triangle.
const float RIVER_SLOPE_FLOOR = 0.5;
const float RIVER_FLAT_SPACING = 4.0;
const float RIVER_JOIN_SPACING = 8.0;
// Beyond the thesis: the largest change of the river half width per unit of length at which a triangle is taken
// to measure one river. Along one river the width changes by a fraction of a percent per unit; a triangle with a
// vertex nearest a finer level's stream (its own narrow width, docs/kernel.md) and one nearest the wide river
// beside it changes by about the river's width over the vertex spacing, and its interpolated distance is no
// river's.
const float WIDTH_SLOPE_LIMIT = 0.25;

// Whether a triangle's interpolated distance (screen derivatives `dd`) and half width `w` (`dw`) measure one river:
// the distance changes at most RIVER_SLOPE_LIMIT and, on a triangle more than RIVER_FLAT_SPACING half widths
// across, at least `slopeFloor` per unit of length, and the width at most WIDTH_SLOPE_LIMIT.
bool measuresOneRiver(float w, vec2 dd, vec2 dw, vec3 px, vec3 py, float slopeFloor) {
    float slope = distanceSlope(dd, px, py);
    bool flatDistance = slope < slopeFloor && fSpacing > RIVER_FLAT_SPACING * w;
    return slope <= RIVER_SLOPE_LIMIT && !flatDistance && distanceSlope(dw, px, py) <= WIDTH_SLOPE_LIMIT;
}

// Beyond the thesis: RIVER_SLOPE_FLOOR for the river pair. Across a straight river the interpolated distance
// changes by one unit per unit of length; where a triangle's vertices lie on either side of the line a river's
// end points along (beyond a tributary's mouth or a source, the distance to the end's sample changes sign there)
// the interpolant is flatter and paints a false stripe across the triangle. The second river is measured at many
// more vertices than the nearest, mostly beside ends: with the nearest's floor, 0.5, such stripes joined rivers
// from orbit into painted 5x5 squares (3 on the diffused world of docs/planet.md); with 0.8, none were added.
const float PAIR_SLOPE_FLOOR = 0.8;

// Beyond the thesis (docs/rendering.md, "Painted confluences"): the share of the pixel in the band |d| < w of
// one slot of the river pair, where the triangle's vertices measured one river in it (the distance's and the
// width's slopes as for the nearest river, above) and `mode` paints it (a river at least as wide as the vertex
// spacing is the mesh's in `auto`); -1 where not. `dd`, `dw`: the slot's screen derivatives.
float pairBand(float d, float w, vec2 dd, vec2 dw, vec3 px, vec3 py, uint mode) {
    bool painted = mode == WATER_PAINTED || (mode == WATER_AUTO && fSpacing >= w);
    if (!painted || w <= 0.0 || !measuresOneRiver(w, dd, dw, px, py, PAIR_SLOPE_FLOOR)) return -1.0;
    float e = abs(dd.x) + abs(dd.y) + 1e-4;
    return 1.0 - smoothBand(w - e, w + e, abs(d));
}

// Beyond the thesis (docs/rendering.md, "Lakes from afar"): the cube faces' axes (normal, u, v; planet/cube.rs
// FACE_AXES), the lake map's layers.
const vec3 FACE_NORMAL[6] = vec3[](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, 1),
                                   vec3(0, 0, -1));
const vec3 FACE_U[6] = vec3[](vec3(0, 0, -1), vec3(0, 0, 1), vec3(1, 0, 0), vec3(1, 0, 0), vec3(1, 0, 0),
                              vec3(-1, 0, 0));
const vec3 FACE_V[6] = vec3[](vec3(0, 1, 0), vec3(0, 1, 0), vec3(0, 0, -1), vec3(0, 0, 1), vec3(0, 1, 0),
                              vec3(0, 1, 0));

// The lake map's texture coordinate towards direction `d` (the face it points through, ties to the lowest face as
// planet/cube.rs face_of) on a map of `side` texels per face edge, one per lattice point.
vec3 lakeMapCoord(vec3 d, float side) {
    vec3 a = abs(d);
    int face = a.x >= a.y && a.x >= a.z ? (d.x >= 0.0 ? 0 : 1)
             : a.y >= a.z               ? (d.y >= 0.0 ? 2 : 3)
                                        : (d.z >= 0.0 ? 4 : 5);
    vec3 p = d / dot(d, FACE_NORMAL[face]);
    vec2 uv = vec2(dot(p, FACE_U[face]), dot(p, FACE_V[face]));
    return vec3(((uv + 1.0) * 0.5 * (side - 1.0) + 0.5) / side, float(face));
}

void main() {
    vec3 sun = normalize(frame.sun.xyz);
    vec3 up = normalize(fDirection);
    vec3 view = normalize(-fPosition);
    if (WATER_PASS == 1) {
        bool river = fRiverWater > 0.5;
        vec2 visible;
        vec3 q = rippleSpace(river, visible);
        // River water covers the basin only: a triangle reaching past the banks is cut at the river's width.
        if (river && abs(fRiver.z) > fRiver.w) discard;
        // Lakes reach the shaders as basins of a vast width: they keep their real depth.
        bool carved = river && fRiver.w <= LAKE_HALF_WIDTH_FLOOR;
        float depth = carved ? riverLookDepth() : max(fRiver.y - fRiver.x, 0.0);
        float opacity = carved ? riverOpacity(abs(fRiver.z) / fRiver.w) : depthOpacity(depth);
        vec4 water = waterSurface(river, depth, opacity, q, visible, up, view, sun);
        if (CLIMATE == 1u) {
            Climate climate = climateAt(up, fMoisture);
            water = river ? withFreshIce(water, fRiver.x, climate, up, sun) : withSeaIce(water, climate, up, sun, 0.5);
        }
        outColor = vec4(atmosphereOn() ? throughAir(water.rgb) : water.rgb, water.a);
        return;
    }
    vec2 visible;
    vec3 q = rippleSpace(true, visible);
    vec2 seaVisible;
    vec3 seaQ = rippleSpace(false, seaVisible);
    // Derivatives in uniform control flow, before any branch.
    vec2 dz = vec2(dFdx(fRiver.z), dFdy(fRiver.z));
    float edge = abs(dz.x) + abs(dz.y) + 1e-4;
    float shoreEdge = fwidth(fRiver.x) + 1e-6;
    float bankEdge = fwidth(fRiver.y - fRiver.x) + 1e-6;
    vec3 px = dFdx(fPosition);
    vec3 py = dFdy(fPosition);
    // The pixel's footprint on the surface (world units), for the lakes drawn from the lake map.
    float footprint = sqrt(max(dot(px, px), dot(py, py)));
    vec2 dw = vec2(dFdx(fRiver.w), dFdy(fRiver.w));
    float joinEdge = fwidth(fBank) + 1e-4;
    vec4 pairX = dFdx(fRiverPair);
    vec4 pairY = dFdy(fRiverPair);
    bool measured = measuresOneRiver(fRiver.w, dz, dw, px, py, RIVER_SLOPE_FLOOR);
    vec3 normal = normalize(fNormal);
    float slope = 1.0 - clamp(dot(normal, up), 0.0, 1.0);
    // The detail also frays the bands' and the rock's borders (by up to a colour-band unit and a tenth of slope).
    float detail = groundDetail();
    Climate climate = Climate(0.0, 0.0, 0.0, 0.0);
    if (CLIMATE == 1u) climate = climateAt(up, fMoisture);
    vec3 albedo = terrainColour(fRiver.x, (detail - 0.5) * 2.0, slope * 3.0 + (detail - 0.5) * 0.3, vec3(detail),
                                climate);
    if (viewMode() == 1) albedo = mix(albedo, levelColour(fLevel), 0.6);
    vec3 diffuse = max(dot(normal, sun), 0.0) * fSunlight;
    float ambient = 0.18 + 0.12 * max(dot(up, sun) + 0.3, 0.0);
    vec3 colour = albedo * (ambient + 0.85 * diffuse);
    // Section 8.4: paint a river the mesh is too coarse to carve (vertices not closer than half its width, the
    // thesis's rule, in `auto`), from the signed distance and width; as water half a colour band deep. Where the
    // distance was measured to different rivers (beyond the thesis, distanceSlope), at a confluence, the signed
    // distances do not interpolate; the two nearest rivers in their order do where the vertices agree on them
    // (the union of both bands), else the distances to the banks (the union of the rivers' water, each vertex
    // measuring the nearest): water where they interpolate below 0 (docs/rendering.md, "Painted confluences").
    uint mode = waterMode();
    bool paint = mode == WATER_PAINTED || (mode == WATER_AUTO && fSpacing >= fRiver.w);
    float inBasin = fRiver.w > 0.0 ? 1.0 - smoothBand(fRiver.w - edge, fRiver.w + edge, abs(fRiver.z)) : 0.0;
    // Only on triangles at most RIVER_JOIN_SPACING half widths across: a vertex beyond a river's end measures the
    // line the river ends on, and from afar a large triangle with one would be painted whole.
    bool joinable = fSpacing <= RIVER_JOIN_SPACING * fRiver.w;
    float joined = joinable ? 1.0 - smoothBand(-joinEdge, joinEdge, fBank) : 0.0;
    float lowRiver = pairBand(fRiverPair.x, fRiverPair.y, vec2(pairX.x, pairY.x), vec2(pairX.y, pairY.y), px, py, mode);
    float highRiver = pairBand(fRiverPair.z, fRiverPair.w, vec2(pairX.z, pairY.z), vec2(pairX.w, pairY.w), px, py, mode);
    bool pairMeasured = lowRiver >= 0.0 && highRiver >= 0.0;
    float nearest = paint ? (measured ? inBasin : pairMeasured ? 0.0 : joined) : 0.0;
    float painted = max(nearest, max(max(lowRiver, highRiver), 0.0));
    // Beyond the thesis (docs/rendering.md, "Water in the terrain mesh"): the sea and the rivers the mesh shows,
    // over the terrain's colour as the water pass blends them: where the terrain lies below the water's surface
    // (what the water pass's depth test decides) and, for a river, within its width (where the water pass cuts
    // it) on triangles with a vertex in the basin (those the water pass draws); both edges antialiased. The sea
    // covers a river's mouth.
    float sea = frame.sun.w;
    bool inMesh = waterInMesh();
    float underSea = inMesh ? 1.0 - smoothBand(-shoreEdge, shoreEdge, fRiver.x - sea) : 0.0;
    float inRiver = inMesh && !paint && fNearBasin > 0.0
                  ? inBasin * smoothBand(-bankEdge, bankEdge, fRiver.y - fRiver.x) : 0.0;
    // Beyond the thesis (docs/rendering.md, "Lakes from afar"): on patches coarser than the precomputed lattice,
    // lakes from the lake map (how far each lattice point lies below the level of the lake that reaches it), to the
    // bilinear contour at their level, in place of the water the coarse mesh's few lake vertices would show. Only
    // there, in patches a lake reaches (drawn by the pipeline with LAKE_MAP 1) and above the sea, is the map read
    // (finer patches draw their lakes in the mesh): one gather, no
    // implicit derivative, so the branch may differ within a quad; the contour is antialiased over the pixel's
    // footprint (taken above, in uniform control flow) times the map's gradient.
    int lakeSlot = lakeMapSlot();
    float lakeCover = 0.0;
    float lakeDepth = 0.0;
    float mapSpacing = frame.planet.x * 1.5707963 / lakeMapCells();
    if (LAKE_MAP == 1u && lakeSlot >= 0 && inMesh && mode == WATER_AUTO && fSpacing > mapSpacing && underSea == 0.0) {
        float side = lakeMapCells() + 1.0;
        vec3 coord = lakeMapCoord(up, side);
        vec4 texels = textureGather(patchTextures[lakeSlot], coord, 0);
        vec2 f = fract(coord.xy * side - 0.5);
        // Gather order: (0, 1), (1, 1), (1, 0), (0, 0).
        float below = mix(mix(texels.w, texels.z, f.x), mix(texels.x, texels.y, f.x), f.y);
        vec2 gradient = vec2(mix(texels.z - texels.w, texels.y - texels.x, f.y),
                             mix(texels.x - texels.w, texels.y - texels.z, f.x)) / mapSpacing;
        float lakeEdge = length(gradient) * footprint + 1e-6;
        float coarse = smoothBand(mapSpacing, 2.0 * mapSpacing, fSpacing);
        lakeCover = coarse * smoothBand(-lakeEdge, lakeEdge, below);
        lakeDepth = below;
        if (fRiver.w > LAKE_HALF_WIDTH_FLOOR) inRiver *= 1.0 - coarse;
    }
    // A river whose water stands above the sea covers the sea beneath it: its bed may dip below sea level near the
    // coast, and the sea's antialiased contour there (underSea between 0 and 1) broke the river's water into lines
    // of bare ground along the contour. At its mouth a river's water comes down to the sea's level and the sea
    // covers it.
    bool riverAbove = fRiver.y > sea && max(inRiver, painted) >= underSea;
    bool seaWater = underSea > 0.0 && !riverAbove;
    bool lakeWater = !seaWater && lakeCover > max(inRiver, painted);
    float cover = seaWater ? underSea : max(max(inRiver, painted), lakeCover);
    // One evaluation of the water's surface for whichever water this pixel shows.
    if (cover > 0.0) {
        bool paintedWater = !seaWater && !lakeWater && painted > 0.0;
        bool standing = seaWater || lakeWater;
        // Lakes in the mesh reach the shaders as basins of a vast width: they keep their real depth.
        bool carvedRiver = !standing && !paintedWater && fRiver.w <= LAKE_HALF_WIDTH_FLOOR;
        float depth = seaWater ? sea - fRiver.x : lakeWater ? lakeDepth
                    : paintedWater || carvedRiver ? riverLookDepth() : fRiver.y - fRiver.x;
        depth = max(depth, 0.0);
        // Painted rivers are opaque (the thesis's painting); carved ones as opaque but at the bank.
        float opacity = paintedWater ? 1.0 : carvedRiver ? riverOpacity(abs(fRiver.z) / fRiver.w) : depthOpacity(depth);
        vec4 water = waterSurface(!standing, depth, opacity, standing ? seaQ : q, standing ? seaVisible : visible, up,
                                  view, sun);
        if (paintedWater && viewMode() == 2) water.rgb = vec3(0.9, 0.1, 0.1) * (ambient + 0.85 * diffuse);
        // The painted rivers shown red stay red (that view shows what is painted).
        if (CLIMATE == 1u && !(paintedWater && viewMode() == 2)) {
            water = seaWater ? withSeaIce(water, climate, up, sun, detail) : withFreshIce(water, fRiver.x, climate, up, sun);
        }
        colour = mix(colour, water.rgb, water.a * cover);
    }
    outColor = vec4(throughAir(colour), 1.0);
}
