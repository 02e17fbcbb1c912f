//! The kernel's shape and variant measured on the device at first use and cached per device and driver
//! (docs/kernel.md, "A kernel that wins on each device").
//!
//! Why measure: the best tile differs by an order of magnitude between devices. On lavapipe 1024-sample tiles win
//! (a workgroup is a loop on one core; shared memory is ordinary cache). On an NVIDIA H200 the same tiles take
//! 28 KiB of shared memory for a 32-invocation workgroup, so few warps fit a multiprocessor and the tiled kernel
//! lost to the simple one (12.9 ms against 7.0); 256-sample tiles in 8x8 blocks won (2.6 ms). Vulkan does not
//! say how many workgroups a multiprocessor holds, so the choice is timed, not derived.

use std::{
    collections::BTreeMap,
    path::{Path, PathBuf},
    sync::{Mutex, OnceLock},
};

use serde::{Deserialize, Serialize};

use super::{run_batch_into, BatchOutputs, KernelTuning, KernelVariant, RiverKernel};
use crate::{
    gpu::{bindless::Bindless, Context, GpuError},
    kernel::{workload, KernelParams, PatchJob},
    named::Named,
    shaders,
};

/// Which kernel variant to run: the faster one measured on the device (the renderer's default), or one named.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KernelChoice {
    /// The faster variant measured on this device (and cached per device and driver).
    Auto,
    /// This variant.
    Fixed(KernelVariant),
}

impl Named for KernelChoice {
    const ALL: &'static [(&'static str, Self)] = &[
        ("auto", Self::Auto),
        ("simple", Self::Fixed(KernelVariant::Simple)),
        ("tiled", Self::Fixed(KernelVariant::Tiled)),
    ];
}

/// The device's measured choice: the fastest tiled shape, and the faster of the two variants with it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tuned {
    /// The fastest tiled shape.
    pub tuning: KernelTuning,
    /// The faster variant with it.
    pub variant: KernelVariant,
    /// Median kernel time of the synthetic workload (below), simple kernel and best tiled shape.
    pub simple_ms: f64,
    /// See `simple_ms`.
    pub tiled_ms: f64,
}

/// Tiled shapes tried (block, tile size): the lavapipe sweep's best (docs/kernel.md), and smaller tiles and larger
/// blocks that keep more workgroups resident on GPUs with a fixed shared-memory budget per multiprocessor.
const CANDIDATES: [([u32; 2], u32); 5] = [
    ([8, 4], 992),
    ([8, 4], 256),
    ([8, 8], 256),
    ([16, 8], 512),
    ([16, 16], 256),
];

/// Patches and repetitions of the measurement.
const PATCHES: usize = 48;
const RIVERS_PER_PATCH: usize = 4;
const REPETITIONS: usize = 3;
const RIVER_WIDTH_SCALE: f32 = 0.25;

/// The tuning for this device and patches of `grid_size` vertices, measured once per process and kept in the
/// cache file (below). `RIVERPLANET_KERNEL_CACHE` names the cache file (`off`: measure, keep nothing); the default
/// is `$XDG_CACHE_HOME/riverplanet/kernel-tuning.json` (or under `~/.cache`).
pub fn tuned(ctx: &Context, grid_size: u32) -> Result<Tuned, GpuError> {
    // One measurement per device in a process, however many renderers start at once.
    static MEASURED: OnceLock<Mutex<BTreeMap<String, Tuned>>> = OnceLock::new();
    let key = device_key(ctx, grid_size);
    let measured = MEASURED.get_or_init(Default::default);
    let mut measured = measured.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(t) = measured.get(&key) {
        return Ok(*t);
    }
    let t = cached(ctx, grid_size, cache_path().as_deref())?;
    measured.insert(key, t);
    Ok(t)
}

/// The tuning from the cache file `path` when this device, driver, patch size and kernel were measured before,
/// else measured now (about 2 s on lavapipe, well under 1 s on a GPU) and added to the file. A file that cannot
/// be read as a cache, or an entry this device cannot run, is replaced.
pub fn cached(ctx: &Context, grid_size: u32, path: Option<&Path>) -> Result<Tuned, GpuError> {
    let key = device_key(ctx, grid_size);
    let mut cache: BTreeMap<String, Tuned> = path
        .and_then(|p| std::fs::read(p).ok())
        .and_then(|bytes| serde_json::from_slice(&bytes).ok())
        .unwrap_or_default();
    // An entry this device cannot run (edited by hand) is measured again.
    if let Some(t) = cache.get(&key).filter(|t| t.tuning.validate(ctx).is_ok()) {
        return Ok(*t);
    }
    let t = measure(ctx, grid_size)?;
    log::info!(
        "kernel tuning measured on {}: {:?} variant, blocks {:?}, {}-sample tiles (simple {:.3} ms, tiled {:.3} ms)",
        ctx.adapter.name, t.variant, t.tuning.tiled_block, t.tuning.tile_size, t.simple_ms, t.tiled_ms
    );
    if let Some(path) = path {
        cache.insert(key, t);
        if let Err(e) = write_atomically(path, &cache) {
            log::warn!("kernel tuning not cached in {}: {e}", path.display());
        }
    }
    Ok(t)
}

/// Times the simple kernel and every valid tiled shape on a synthetic workload of `PATCHES` patches crossed by
/// `RIVERS_PER_PATCH` x 1-3 random rivers (Section 6.4's sampling), the median of `REPETITIONS` runs each.
pub fn measure(ctx: &Context, grid_size: u32) -> Result<Tuned, GpuError> {
    let params = KernelParams {
        influence_distance: 20.0,
        basin_depth: 0.1,
        sea_level: 0.0,
        basin_water_offset: 0.001,
        sample_floor: 0.25,
    };
    // Rivers a twentieth to a fifth of the influence distance wide, as the planet's are at the levels where most
    // patches are made (the generator draws widths in proportion to the distance it is given).
    let narrow = KernelParams {
        influence_distance: params.influence_distance * RIVER_WIDTH_SCALE,
        ..params
    };
    let rivers = workload::random_patches(36, PATCHES * RIVERS_PER_PATCH, grid_size, 1.0, &narrow);
    let patches: Vec<(f32, Vec<_>)> = rivers
        .chunks(RIVERS_PER_PATCH)
        .map(|c| (1.0, c.iter().flat_map(|(_, s)| s.iter().copied()).collect()))
        .collect();
    let jobs = PatchJob::from_pairs(&patches);
    let mut bindless = Bindless::new(ctx, PATCHES as u32 + 16)?;
    // One set of output textures for every run (freed slots return only once the GPU is done with them).
    let outputs = BatchOutputs::new(ctx, &mut bindless, jobs.len(), grid_size)?;
    let time = |tuning: KernelTuning, variant| -> Result<f64, GpuError> {
        let kernel = RiverKernel::new(ctx, &bindless, grid_size, tuning)?;
        let mut runs = Vec::new();
        // One warm-up run, then the measured ones.
        for _ in 0..=REPETITIONS {
            let result = run_batch_into(
                ctx,
                &bindless,
                &kernel,
                variant,
                &jobs,
                (&[], &[]),
                &params,
                &outputs,
            );
            match result {
                Ok(r) => runs.push(r.timings.iter().map(|t| t.ms).sum::<f64>()),
                Err(e) => {
                    return Err(e);
                }
            }
        }
        runs.remove(0);
        runs.sort_by(f64::total_cmp);
        Ok(runs[runs.len() / 2])
    };
    let base = KernelTuning::for_device(ctx);
    let timed = (|| {
        let simple_ms = time(base, KernelVariant::Simple)?;
        let mut best: Option<(KernelTuning, f64)> = None;
        for (block, tile_size) in CANDIDATES {
            let tuning = KernelTuning::fitted(ctx, block, tile_size);
            if tuning.validate(ctx).is_err() || best.is_some_and(|(t, _)| t == tuning) {
                continue;
            }
            let ms = time(tuning, KernelVariant::Tiled)?;
            if best.is_none_or(|(_, b)| ms < b) {
                best = Some((tuning, ms));
            }
        }
        Ok::<_, GpuError>((simple_ms, best))
    })();
    let (simple_ms, best) = timed?;
    let (tuning, tiled_ms) = best.unwrap_or((base, f64::INFINITY));
    Ok(Tuned {
        tuning,
        variant: if tiled_ms <= simple_ms {
            KernelVariant::Tiled
        } else {
            KernelVariant::Simple
        },
        simple_ms,
        tiled_ms,
    })
}

/// What the measurement depends on: the device, its driver, the patch size and the kernels' code.
pub fn device_key(ctx: &Context, grid_size: u32) -> String {
    let p = &ctx.properties;
    // FNV-1a of the kernels' SPIR-V: a new kernel is measured again.
    let code = [
        shaders::KERNEL_SIMPLE_COMP,
        shaders::KERNEL_TILED_COMP,
        shaders::KERNEL_REACH_COMP,
    ]
    .iter()
    .flat_map(|s| s.iter())
    .fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
    });
    format!(
        "{} [{:04x}:{:04x}] {} {} | {grid_size}x{grid_size} | kernels {code:016x}",
        ctx.adapter.name,
        p.vendor_id,
        p.device_id,
        ctx.adapter.driver_name,
        ctx.adapter.driver_info
    )
}

fn cache_path() -> Option<PathBuf> {
    match std::env::var_os("RIVERPLANET_KERNEL_CACHE") {
        Some(v) if v == "off" => None,
        Some(v) => Some(PathBuf::from(v)),
        None => std::env::var_os("XDG_CACHE_HOME")
            .map(PathBuf::from)
            .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
            .map(|d| d.join("riverplanet").join("kernel-tuning.json")),
    }
}

/// Writes the cache through a temporary file and a rename, so that a reader never sees half a file.
fn write_atomically(path: &Path, cache: &BTreeMap<String, Tuned>) -> std::io::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    std::fs::write(&tmp, serde_json::to_vec_pretty(cache)?)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}
