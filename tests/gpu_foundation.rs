//! The Vulkan foundation on a real device: compute dispatch with readback, timestamps, the staging upload path.

mod common;

use riverplanet::{
    gpu::{
        bindless::{Bindless, SlotLayer},
        layers::{LayerKind, LayerPool},
        pipeline::{BufferSetLayout, ComputeDesc, ComputePipeline},
        Access, Buffer, BufferDesc, Context, Extent2D, Format, ImageDesc, MemoryLocation, Profiler,
        Recorder,
    },
    shaders,
};

/// The fill shader's pieces: an output buffer of `count` floats, a host-visible buffer to read it back into, its
/// set layout and pipeline (`out[i] = i * a + b`, push constants a, b, count).
struct Fill {
    out: Buffer,
    readback: Buffer,
    sets: BufferSetLayout,
    pipeline: ComputePipeline,
}

impl Fill {
    fn new(ctx: &Context, count: u32) -> Self {
        let size = count as u64 * 4;
        let buffer = |name, uses, location| {
            ctx.create_buffer(&BufferDesc {
                name,
                size,
                uses,
                location,
            })
            .unwrap()
        };
        let sets = BufferSetLayout::new(ctx, 1, "fill set").unwrap();
        let pipeline = ComputePipeline::new(
            ctx,
            &ComputeDesc {
                name: "fill",
                spirv: shaders::FILL_COMP,
                set_layouts: &[sets.layout],
                push_constant_bytes: 12,
                specialization: &[],
                full_subgroups: None,
            },
        )
        .unwrap();
        Self {
            out: buffer(
                "fill output",
                &[Access::ComputeWrite, Access::TransferRead],
                MemoryLocation::GpuOnly,
            ),
            readback: buffer(
                "fill readback",
                &[Access::TransferWrite, Access::HostRead],
                MemoryLocation::GpuToCpu,
            ),
            sets,
            pipeline,
        }
    }
}

/// Issue 37: a pipeline, its set layout and the buffer it writes, dropped after a dispatch that uses them was
/// recorded and before that recording is submitted, live until the dispatch has run: a garbage collection meanwhile
/// (another frame's) frees none of them, the result is right, and validation reports no use of a destroyed object.
/// Tagged with the last submitted value, as they were before, that collection freed them.
#[test]
fn objects_dropped_while_a_recording_uses_them_live_until_it_has_run() {
    let Some(own) = common::own_gpu() else { return };
    let ctx = &own;
    ctx.run_and_wait("first submission", |_| Ok(())).unwrap();
    const COUNT: u32 = 256;
    let Fill {
        out,
        readback,
        sets,
        pipeline,
    } = Fill::new(ctx, COUNT);
    let push: [u32; 3] = [2.0f32.to_bits(), 1.0f32.to_bits(), COUNT];
    let mut rec = Recorder::begin(ctx, "drop while recorded").unwrap();
    let set = rec.buffer_set(&sets, &[&out]).unwrap();
    rec.use_buffer(&out, &[Access::ComputeWrite]);
    rec.dispatch(
        &pipeline,
        &[set],
        bytemuck::cast_slice(&push),
        [COUNT.div_ceil(64), 1, 1],
    );
    rec.copy_buffer(&out, &readback, COUNT as u64 * 4);
    let before = ctx.retired_objects();
    drop(pipeline);
    drop(sets);
    drop(out);
    assert_eq!(ctx.retired_objects(), before + 3);
    ctx.collect_garbage();
    assert_eq!(
        ctx.retired_objects(),
        before + 3,
        "objects a recorded command uses were freed before its submission"
    );
    let id = rec.submit().unwrap();
    ctx.wait(id).unwrap();
    assert_eq!(
        ctx.retired_objects(),
        0,
        "the submission's objects outlived it"
    );
    let values: &[f32] = bytemuck::cast_slice(readback.mapped().unwrap());
    for (i, v) in values.iter().enumerate() {
        assert_eq!(*v, i as f32 * 2.0 + 1.0, "value {i}");
    }
    common::assert_no_validation_errors(ctx);
}

#[test]
fn compute_dispatch_reads_back_and_is_timed() {
    let Some(ctx) = common::gpu() else { return };
    const COUNT: u32 = 1000;
    let size = COUNT as u64 * 4;
    let Fill {
        out,
        readback,
        sets,
        pipeline,
    } = Fill::new(ctx, COUNT);
    let mut profiler = Profiler::new(ctx, 4, "fill timestamps").unwrap();

    let push: [u32; 3] = [0.5f32.to_bits(), 3.0f32.to_bits(), COUNT];
    ctx.run_and_wait("fill", |rec| {
        let set = rec.buffer_set(&sets, &[&out])?;
        profiler.scope(rec, "fill kernel", |rec| {
            rec.use_buffer(&out, &[Access::ComputeWrite]);
            rec.dispatch(
                &pipeline,
                &[set],
                bytemuck::cast_slice(&push),
                [COUNT.div_ceil(64), 1, 1],
            );
        })?;
        rec.copy_buffer(&out, &readback, size);
        Ok(())
    })
    .unwrap();

    let values: &[f32] = bytemuck::cast_slice(readback.mapped().unwrap());
    for (i, v) in values.iter().enumerate() {
        assert_eq!(*v, i as f32 * 0.5 + 3.0, "value {i}");
    }
    let timings = profiler.read(ctx).unwrap();
    assert_eq!(timings.len(), 1);
    assert_eq!(timings[0].name, "fill kernel");
    assert!(
        timings[0].ms > 0.0 && timings[0].ms < 10_000.0,
        "timestamp pair gave {} ms",
        timings[0].ms
    );

    drop(out);
    drop(readback);
    ctx.wait_idle().unwrap();
    common::assert_no_validation_errors(ctx);
}

#[test]
fn staging_upload_reaches_device_local_buffer() {
    let Some(ctx) = common::gpu() else { return };
    let data: Vec<u32> = (0..4096).map(|i| i * 7 + 1).collect();
    let size = (data.len() * 4) as u64;
    let device_local = ctx
        .create_buffer(&BufferDesc {
            name: "upload target",
            size,
            uses: &[
                Access::ComputeWrite,
                Access::TransferWrite,
                Access::TransferRead,
            ],
            location: MemoryLocation::GpuOnly,
        })
        .unwrap();
    let readback = ctx
        .create_buffer(&BufferDesc {
            name: "upload readback",
            size,
            uses: &[Access::TransferWrite, Access::HostRead],
            location: MemoryLocation::GpuToCpu,
        })
        .unwrap();
    ctx.run_and_wait("upload", |rec| {
        rec.upload_buffer(&device_local, 0, bytemuck::cast_slice(&data))?;
        rec.copy_buffer(&device_local, &readback, size);
        Ok(())
    })
    .unwrap();
    let back: &[u32] = bytemuck::cast_slice(readback.mapped().unwrap());
    assert_eq!(back, &data[..]);
    drop(device_local);
    drop(readback);
    ctx.wait_idle().unwrap();
    common::assert_no_validation_errors(ctx);
}

/// Dropping a buffer or an image retires it: it stays allocated while a submission that used it may run, and once
/// the GPU is done it is kept for a request of its shape, or freed (`release_recycled`), without a call to free it.
#[test]
fn dropped_buffers_and_images_are_kept_or_freed_once_the_gpu_is_done() {
    // A context of its own: the shared one's allocations change with the other tests.
    let Some(ctx) = common::own_gpu() else { return };
    let before = ctx.live_allocations();
    let buffer = ctx
        .create_buffer(&BufferDesc {
            name: "dropped buffer",
            size: 1 << 20,
            uses: &[Access::TransferWrite],
            location: MemoryLocation::GpuOnly,
        })
        .unwrap();
    let image = ctx
        .create_image(&ImageDesc {
            name: "dropped image",
            extent: Extent2D {
                width: 64,
                height: 64,
            },
            layers: 1,
            format: Format::R32_SFLOAT,
            uses: &[Access::GraphicsSampled, Access::TransferWrite],
            array: false,
        })
        .unwrap();
    assert_eq!(ctx.live_allocations(), before + 2);
    let mut rec = riverplanet::gpu::Recorder::begin(&ctx, "fill before drop").unwrap();
    rec.fill_buffer(&buffer, 7);
    rec.overwrite_images(&[&image], &[Access::TransferWrite]);
    let submitted = rec.submit().unwrap();
    drop(buffer);
    drop(image);
    // Retired, not freed: the submission may still use them.
    assert_eq!(ctx.live_allocations(), before + 2);
    ctx.wait(submitted).unwrap();
    ctx.collect_garbage();
    // Done with on the GPU: kept for reuse (gpu/retire.rs), not in use.
    assert_eq!(ctx.retired_objects(), 0);
    assert_eq!(ctx.recycled_objects(), 2);
    assert_eq!(ctx.live_allocations(), before + 2);
    // A request of the same shape takes the kept buffer instead of creating one.
    let created = ctx.created_resources();
    let again = ctx
        .create_buffer(&BufferDesc {
            name: "buffer again",
            size: (1 << 20) - 100,
            uses: &[Access::TransferWrite],
            location: MemoryLocation::GpuOnly,
        })
        .unwrap();
    assert_eq!(ctx.created_resources(), created);
    assert_eq!(ctx.recycled_objects(), 1);
    drop(again);
    ctx.release_recycled();
    assert_eq!(ctx.recycled_objects(), 0);
    assert_eq!(ctx.live_allocations(), before);
}

/// Issue "One way to use the GPU": an image remembers what it was last recorded for, so a caller names only the
/// next use. An upload, a copy out, a second upload over it and a second copy, across two submissions: each copy
/// reads what was uploaded just before it, and synchronization validation finds no hazard (a barrier that forgot
/// the upload would let the copy read before the write, from a layout that discards it).
#[test]
fn images_carry_their_last_use_from_barrier_to_barrier() {
    let Some(ctx) = common::gpu_with_synchronization_validation() else {
        return;
    };
    let image = ctx
        .create_image(&ImageDesc {
            name: "tracked image",
            extent: Extent2D {
                width: 8,
                height: 8,
            },
            layers: 1,
            format: Format::R32_SFLOAT,
            // An attachment's usage: not shader-visible, so each use has its own layout (gpu/access.rs).
            uses: &[
                Access::ColorAttachment,
                Access::TransferWrite,
                Access::TransferRead,
            ],
            array: false,
        })
        .unwrap();
    let readback = ctx
        .create_buffer(&BufferDesc {
            name: "tracked image readback",
            size: 2 * 64 * 4,
            uses: &[Access::TransferWrite, Access::HostRead],
            location: MemoryLocation::GpuToCpu,
        })
        .unwrap();
    let texels = |k: f32| (0..64).map(|i| i as f32 + k).collect::<Vec<f32>>();
    let round = |rec: &mut Recorder, k: f32, offset: u64| {
        rec.overwrite_images(&[&image], &[Access::TransferWrite]);
        rec.upload_image_layer(&image, 0, bytemuck::cast_slice(&texels(k)))?;
        rec.use_images(&[&image], &[Access::TransferRead]);
        rec.copy_image_to_buffer(&image, &readback, offset);
        Ok(())
    };
    ctx.run_and_wait("first round", |rec| round(rec, 0.0, 0))
        .unwrap();
    ctx.run_and_wait("second round", |rec| {
        round(rec, 1000.0, 256)?;
        rec.use_buffer(&readback, &[Access::HostRead]);
        Ok(())
    })
    .unwrap();
    let read: &[f32] = bytemuck::cast_slice(readback.mapped().unwrap());
    assert_eq!(&read[..64], &texels(0.0)[..]);
    assert_eq!(&read[64..], &texels(1000.0)[..]);
    common::assert_no_validation_errors(ctx);
}

/// Issue 37, item 4: textures of one kind are layers of a few array images. Each texture's layers are its own
/// (written and read back apart from its neighbours'), every image but the last is full, a pool holds no more
/// than its capacity, and a released place is handed out again once the GPU is done with it.
#[test]
fn textures_share_array_images_each_in_layers_of_its_own() {
    let Some(ctx) = common::gpu() else { return };
    let mut bindless = Bindless::new(ctx, 8).unwrap();
    let kind = LayerKind {
        name: "test textures",
        extent: Extent2D {
            width: 4,
            height: 4,
        },
        format: Format::R32_SFLOAT,
        layers_per_texture: 3,
        uses: &[
            Access::TransferWrite,
            Access::TransferRead,
            Access::GraphicsSampled,
        ],
    };
    let capacity = 200;
    let mut pool = LayerPool::new(kind, capacity).unwrap();
    let places: Vec<SlotLayer> = (0..capacity)
        .map(|_| pool.allocate(ctx, &mut bindless).unwrap().unwrap())
        .collect();
    assert!(pool.allocate(ctx, &mut bindless).unwrap().is_none());
    // 85 textures of 3 layers an image of 256 layers: three images.
    assert_eq!(pool.image_count(), 3);
    let mut distinct = places.clone();
    distinct.sort_by_key(|p| p.shader_index());
    distinct.dedup();
    assert_eq!(distinct.len(), capacity);
    assert!(places
        .iter()
        .all(|p| p.layer % 3 == 0 && p.layer + 3 <= 256));

    let texels = |k: usize, layer: u32| -> Vec<f32> {
        (0..16)
            .map(|i| (k * 1000 + layer as usize * 100 + i) as f32)
            .collect()
    };
    let bytes_each = 3 * 16 * 4;
    let readback = ctx
        .create_buffer(&BufferDesc {
            name: "layer readback",
            size: (capacity * bytes_each) as u64,
            uses: &[Access::TransferWrite, Access::HostRead],
            location: MemoryLocation::GpuToCpu,
        })
        .unwrap();
    ctx.run_and_wait("layers written and read", |rec| {
        let images = pool.images(places.iter().copied());
        assert_eq!(images.len(), 3);
        rec.use_images(&images, &[Access::TransferWrite]);
        for (k, place) in places.iter().enumerate() {
            for layer in 0..3 {
                let data = texels(k, layer);
                let image = pool.image(*place).unwrap();
                rec.upload_image_layer(image, place.layer + layer, bytemuck::cast_slice(&data))?;
            }
        }
        rec.use_images(&images, &[Access::TransferRead]);
        for (k, place) in places.iter().enumerate() {
            let layers = place.layer..place.layer + 3;
            let offset = (k * bytes_each) as u64;
            rec.copy_layers_to_buffer(pool.image(*place).unwrap(), layers, &readback, offset);
        }
        rec.use_buffer(&readback, &[Access::HostRead]);
        Ok(())
    })
    .unwrap();
    let read: &[f32] = bytemuck::cast_slice(readback.mapped().unwrap());
    for k in 0..capacity {
        let expected: Vec<f32> = (0..3).flat_map(|layer| texels(k, layer)).collect();
        assert_eq!(&read[k * 48..(k + 1) * 48], &expected[..], "texture {k}");
    }

    // The GPU is done with everything submitted: a released place comes back.
    pool.release(ctx, places[100]);
    assert_eq!(pool.pending_release(), 1);
    assert_eq!(
        pool.allocate(ctx, &mut bindless).unwrap(),
        Some(places[100])
    );
    assert_eq!(pool.image_count(), 3);
    pool.release_slots(ctx, &mut bindless);
    common::assert_no_validation_errors(ctx);
}
