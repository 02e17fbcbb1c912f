// Section 8.4: which water a triangle of a drawn quadrant gets, and where its vertices lie. Shared by the
// thesis's geometry shader (terrain.geom) and, beyond the thesis, the compute pass that makes the same choice for
// cached patches (water_triangles.comp) and the vertex shader that draws its choice (water_surface.vert). Needs
// terrain_common.glsl; waterVertex also terrain_interface.glsl with TERRAIN_WRITER.

const uint WATER_NONE = 0u;
const uint WATER_RIVER = 1u;      // river water, cut at the river's width in the fragment shader
const uint WATER_RIVER_SEA = 2u;  // river water reaching below sea level, not cut
const uint WATER_SEA = 3u;        // the sea

// From the triangle's three surfaces (final height, water height, signed distance, half width) and the patch's
// vertex spacing: river water where any vertex lies in a river basin (|signed distance| < half width) and the
// mesh shows the river (the thesis's rule: vertices closer than half the river's width, in `auto`), else the sea
// where any vertex lies below sea level.
uint waterKind(vec4 r0, vec4 r1, vec4 r2, float spacing) {
    float seaLevel = frame.sun.w;
    bool inBasin = inRiverBasin(r0) || inRiverBasin(r1) || inRiverBasin(r2);
    bool belowSea = r0.x < seaLevel || r1.x < seaLevel || r2.x < seaLevel;
    float widest = max(r0.w, max(r1.w, r2.w));
    uint mode = waterMode();
    bool paint = mode == WATER_PAINTED || (mode == WATER_AUTO && spacing >= widest);
    if (inBasin && !paint) return belowSea ? WATER_RIVER_SEA : WATER_RIVER;
    return belowSea ? WATER_SEA : WATER_NONE;
}

#ifdef TERRAIN_WRITER
// The water vertex of `kind` above a terrain vertex of `p` (`local`: its offset from the patch centre, `surface`
// as above, `direction`: unit, from the planet's centre). Flow and air are the terrain vertex's, set by the caller.
SurfaceVertex waterVertex(PatchInstance p, uint kind, vec3 local, vec4 surface, vec3 direction) {
    float water = kind == WATER_SEA ? frame.sun.w : surface.y;
    // Up from the terrain vertex to the water (a small difference: precise at any planet size).
    vec3 lifted = local + direction * (water - surface.x);
    SurfaceVertex s;
    s.position = p.centreRel.xyz + lifted;
    s.normal = direction;
    s.river = vec4(surface.x, water, surface.z, surface.w);
    s.direction = direction;
    s.detail = p.detail.xyz + lifted;
    s.riverWater = kind == WATER_RIVER;
    s.bank = 0.0;
    s.pair = vec4(FAR_FROM_RIVERS, 0.0, FAR_FROM_RIVERS, 0.0);
    s.inBasin = false;
    s.level = p.centreRel.w;
    s.spacing = p.centreDir.w;
    return s;
}
#endif
