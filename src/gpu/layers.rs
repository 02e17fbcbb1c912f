//! Textures of one kind as layers of a few array images (fintelia/terra's level slots): an array image takes one
//! bindless slot and holds [`LAYERS_PER_SLOT`] layers, a texture takes `layers_per_texture` of them. One
//! allocation and one descriptor serve a page of textures instead of one each, and shaders index by a layer
//! rather than by a descriptor that differs from patch to patch.

use super::{
    bindless::{Bindless, SlotLayer, LAYERS_PER_SLOT},
    retire::Released,
    Access, Context, Extent2D, Format, GpuError, Image, ImageDesc,
};

/// The shape of the textures a [`LayerPool`] holds.
#[derive(Clone, Copy, Debug)]
pub struct LayerKind {
    /// Debug name of the array images (numbered).
    pub name: &'static str,
    /// Texels across and down.
    pub extent: Extent2D,
    /// Texel format.
    pub format: Format,
    /// Layers of one texture.
    pub layers_per_texture: u32,
    /// Every way the textures are used.
    pub uses: &'static [Access],
}

/// Array images of one kind of texture, made as they are needed (up to `capacity` textures), with the free
/// textures' places.
pub struct LayerPool {
    kind: LayerKind,
    capacity: usize,
    pages: Vec<(SlotLayer, Image)>,
    free: Vec<SlotLayer>,
    /// Released places, until no submitted frame reads them.
    released: Released<SlotLayer>,
    in_use: usize,
}

impl LayerPool {
    /// A pool of at most `capacity` textures of `kind`; no image is made until one is asked for.
    pub fn new(kind: LayerKind, capacity: usize) -> Result<Self, GpuError> {
        if kind.layers_per_texture == 0 || kind.layers_per_texture > LAYERS_PER_SLOT {
            return Err(GpuError::Invalid(format!(
                "{}: {} layers a texture, outside 1 to {LAYERS_PER_SLOT}",
                kind.name, kind.layers_per_texture
            )));
        }
        Ok(Self {
            kind,
            capacity,
            pages: Vec::new(),
            free: Vec::new(),
            released: Released::default(),
            in_use: 0,
        })
    }

    /// A pool holding exactly `count` textures of `kind`, and their places (for a batch made at once, as the
    /// tests and benchmarks make theirs); on failure every slot taken is given back.
    pub fn filled(
        kind: LayerKind,
        count: usize,
        ctx: &Context,
        bindless: &mut Bindless,
    ) -> Result<(Self, Vec<SlotLayer>), GpuError> {
        let mut pool = Self::new(kind, count)?;
        let mut places = Vec::with_capacity(count);
        while places.len() < count {
            let place = pool.allocate(ctx, bindless).and_then(|place| {
                place.ok_or_else(|| {
                    GpuError::Invalid(format!("no room for {count} {} textures", kind.name))
                })
            });
            match place {
                Ok(place) => places.push(place),
                Err(e) => {
                    pool.release_slots(ctx, bindless);
                    return Err(e);
                }
            }
        }
        Ok((pool, places))
    }

    /// Textures one array image holds.
    pub fn textures_per_image(&self) -> u32 {
        LAYERS_PER_SLOT / self.kind.layers_per_texture
    }

    /// Array images a pool of `capacity` textures of `layers_per_texture` layers makes at most.
    pub fn images_for(capacity: usize, layers_per_texture: u32) -> usize {
        capacity.div_ceil((LAYERS_PER_SLOT / layers_per_texture.max(1)) as usize)
    }

    /// A free texture's place: a released one whose frames have finished, or one of a new array image (which
    /// takes a bindless slot). `Ok(None)` when `capacity` textures are in use or still read by frames in flight.
    pub fn allocate(
        &mut self,
        ctx: &Context,
        bindless: &mut Bindless,
    ) -> Result<Option<SlotLayer>, GpuError> {
        let full = |pool: &Self| pool.in_use + pool.released.len() >= pool.capacity;
        if self.free.is_empty() || full(self) {
            self.released.reclaim_into(ctx, &mut self.free);
        }
        if full(self) {
            return Ok(None);
        }
        if self.free.is_empty() {
            self.add_image(ctx, bindless)?;
        }
        let place = self.free.pop();
        self.in_use += place.is_some() as usize;
        Ok(place)
    }

    /// Returns a texture's place once every submission made so far has completed.
    pub fn release(&mut self, ctx: &Context, place: SlotLayer) {
        debug_assert!(!self.free.contains(&place));
        self.in_use -= 1;
        self.released.push(ctx, place);
    }

    /// Places released but still read by frames in flight.
    pub fn pending_release(&self) -> usize {
        self.released.len()
    }

    /// The array image `place` lies in.
    pub fn image(&self, place: SlotLayer) -> Option<&Image> {
        self.pages
            .iter()
            .find(|(first, _)| first.slot == place.slot)
            .map(|(_, image)| image)
    }

    /// The array images `places` lie in, each once, in the order of their first place.
    pub fn images<'a>(&'a self, places: impl IntoIterator<Item = SlotLayer>) -> Vec<&'a Image> {
        let mut images: Vec<&'a Image> = Vec::new();
        for place in places {
            if let Some(image) = self.image(place) {
                if !images.iter().any(|i| std::ptr::eq(*i, image)) {
                    images.push(image);
                }
            }
        }
        images
    }

    /// Bytes of one texture.
    pub fn texture_bytes(&self) -> u64 {
        let kind = &self.kind;
        (kind.extent.width * kind.extent.height * kind.layers_per_texture) as u64
            * texel_bytes(kind.format)
    }

    /// Array images made so far.
    pub fn image_count(&self) -> usize {
        self.pages.len()
    }

    /// Gives the images' slots back to `bindless` (for a pool that ends before its set); the images are retired
    /// as the pool drops.
    pub fn release_slots(self, ctx: &Context, bindless: &mut Bindless) {
        for (first, _) in &self.pages {
            bindless.release(ctx, first.slot);
        }
    }

    fn add_image(&mut self, ctx: &Context, bindless: &mut Bindless) -> Result<(), GpuError> {
        let slot = bindless.allocate(ctx).ok_or_else(|| {
            GpuError::Invalid(format!(
                "all {} bindless slots are in use: none left for another {} image",
                bindless.capacity, self.kind.name
            ))
        })?;
        let textures = self.textures_per_image();
        let image = ctx.create_image(&ImageDesc {
            name: &format!("{} {}", self.kind.name, self.pages.len()),
            extent: self.kind.extent,
            layers: textures * self.kind.layers_per_texture,
            format: self.kind.format,
            uses: self.kind.uses,
            array: true,
        });
        let image = match image {
            Ok(image) => image,
            Err(e) => {
                bindless.release(ctx, slot);
                return Err(e);
            }
        };
        let storage = self.kind.uses.contains(&Access::ComputeWrite);
        bindless.write(ctx, slot, &image, storage);
        // Lowest layers first.
        self.free.extend((0..textures).rev().map(|k| SlotLayer {
            slot,
            layer: k * self.kind.layers_per_texture,
        }));
        self.pages.push((SlotLayer::whole(slot), image));
        Ok(())
    }
}

fn texel_bytes(format: Format) -> u64 {
    match format {
        Format::R32G32B32A32_SFLOAT => 16,
        Format::R16G16B16A16_SFLOAT | Format::R32G32_SFLOAT => 8,
        _ => 4,
    }
}
