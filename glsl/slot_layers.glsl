// A patch texture's place in the bindless arrays (gpu::bindless::SlotLayer, docs/rendering.md "Patch textures as
// layers"): the slot of an array image times LAYERS_PER_SLOT plus the texture's first layer in it.
#ifndef SLOT_LAYERS_GLSL
#define SLOT_LAYERS_GLSL
const uint LAYERS_PER_SLOT = 256u;

uint slotOf(uint place) { return place / LAYERS_PER_SLOT; }
uint layerOf(uint place) { return place % LAYERS_PER_SLOT; }
int slotOf(int place) { return place >> 8; }
int layerOf(int place) { return place & 255; }
#endif
