//! `riverplanet bench kernel | flight`: runs a benchmark, prints its summary and writes its reports.

use riverplanet::{
    bench,
    gpu::{Context, ContextOptions},
    kernel::gpu::{autotune, KernelTuning},
};

use super::BenchCommand;
use crate::{check_output, check_validation, load_config, write_json};

pub fn run_bench(options: &ContextOptions, what: BenchCommand) -> anyhow::Result<()> {
    match what {
        BenchCommand::Kernel {
            planet,
            stress,
            frames,
            parent_reuse,
            repetitions,
            simple_workgroup,
            tiled_block,
            tile_size,
            json,
        } => {
            let (config, _) = load_config(planet.config.as_deref())?;
            if let Some(path) = &json {
                check_output("--json", path, false)?;
            }
            let world = super::progress::build_world(&config, planet.seed)?;
            let ctx = Context::new(options)?;
            let tuned = autotune::tuned(&ctx, config.rendering.vertices)?.tuning;
            let tuning = KernelTuning {
                simple_workgroup: simple_workgroup.unwrap_or(tuned.simple_workgroup),
                tiled_block: tiled_block.unwrap_or(tuned.tiled_block),
                tile_size: tile_size.unwrap_or(tuned.tile_size),
            };
            if parent_reuse {
                let report = bench::reuse::reuse_bench(&ctx, &world, frames, repetitions, tuning)?;
                print!("{}", report.summary());
                if let Some(path) = json {
                    write_json(&path, &report)?;
                }
                return Ok(());
            }
            let report =
                bench::kernel::kernel_bench(&ctx, &world, stress, frames, repetitions, tuning)?;
            let v = &report.variants;
            println!(
                "device {} | {} patches, {} samples, {} vertex-sample pairs ({} within reach) | rayon threads {}, \
                 LP_NUM_THREADS {}, RAYON_NUM_THREADS {}",
                report.device,
                report.patches,
                report.samples,
                report.pairs,
                report.relevant_pairs,
                report.threads.rayon_threads_used,
                report.threads.lp_num_threads.as_deref().unwrap_or("unset"),
                report.threads.rayon_num_threads.as_deref().unwrap_or("unset"),
            );
            println!("  cpu single   {:>10.3} ms", v.cpu_single.kernel_ms);
            println!("  cpu rayon    {:>10.3} ms", v.cpu_rayon.kernel_ms);
            for (name, t) in [("gpu simple", &v.gpu_simple), ("gpu tiled", &v.gpu_tiled)] {
                println!(
                    "  {name:<12} {:>10.3} ms kernel, {:>10.3} ms end to end",
                    t.kernel_ms,
                    t.end_to_end_ms.unwrap_or(f64::NAN)
                );
            }
            println!(
                "  tiled/simple {:.3} | cpu single / gpu tiled: {:.2}x kernel, {:.2}x end to end | max |diff| {:.3e} \
                 = {:.2e} of the height range {:?}",
                report.ratios.tiled_over_simple,
                report.ratios.cpu_single_over_gpu_tiled_kernel,
                report.ratios.cpu_single_over_gpu_tiled_end_to_end,
                report.max_abs_diff,
                report.relative_diff,
                report.height_range
            );
            for (variant, diffs) in [
                ("gpu simple", &report.max_abs_diff_by_output.gpu_simple),
                ("gpu tiled", &report.max_abs_diff_by_output.gpu_tiled),
            ] {
                for d in diffs.iter().filter(|d| d.max_abs_diff > 0.0) {
                    println!(
                        "  {variant:<12} {:<15} max |diff| {:.3e} at patch {} vertex {:?}: cpu {} gpu {}",
                        d.output, d.max_abs_diff, d.patch, d.vertex, d.expected, d.actual
                    );
                }
            }
            check_validation(&ctx)?;
            if let Some(path) = json {
                write_json(&path, &report)?;
            }
            Ok(())
        }
        BenchCommand::Flight {
            planet,
            stress,
            descent,
            path,
            hole_images,
            frame_images,
            no_morphing,
            no_parent_reuse,
            lod_rule,
            frames_in_flight,
            frames,
            atmosphere,
            vertex_cache,
            water_in_mesh,
            speed,
            size,
            no_kernel_comparison,
            no_water_comparison,
            json,
            summary_only,
            csv,
        } => {
            let (config, _) = load_config(planet.config.as_deref())?;
            for (argument, path) in [("--json", Some(&json)), ("--csv", csv.as_ref())] {
                if let Some(path) = path {
                    check_output(argument, path, false)?;
                }
            }
            for dir in hole_images.iter().chain(&frame_images) {
                std::fs::create_dir_all(dir)
                    .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", dir.display()))?;
            }
            let path = path
                .map(|p| {
                    riverplanet::runtime::camera_path::CameraPath::load(&p).map_err(crate::usage)
                })
                .transpose()?;
            for (k, frame) in path.iter().flat_map(|p| p.frames.iter().enumerate()) {
                super::render::check_path_frame(frame, &config)
                    .map_err(|e| crate::usage(format!("--path: frame {k}: {e}")))?;
            }
            let frames = path.as_ref().map_or(frames, |p| p.frames.len() as u32);
            // Before any work: a device that cannot draw is refused here.
            let ctx = Context::new(&ContextOptions {
                draws: true,
                ..options.clone()
            })?;
            let world = super::progress::build_world(&config, planet.seed)?;
            let progress = super::progress::Progress::start("flight");
            progress.count("flight", frames as u64);
            let options = bench::flight::FlightOptions {
                frames,
                stress,
                speed,
                size,
                compare_kernels: !no_kernel_comparison,
                compare_water_modes: !no_water_comparison,
                descent,
                path,
                hole_images,
                frame_images,
                morphing: !no_morphing,
                parent_reuse: !no_parent_reuse,
                lod_rule,
                frames_in_flight,
                atmosphere: atmosphere.on(),
                vertex_cache: vertex_cache.on(),
                water_in_mesh: water_in_mesh.on(),
            };
            let report = bench::flight::flight_bench(&ctx, &world, &options, |mode, frame| {
                progress.say(mode.to_string());
                progress.set(frame as u64 + 1);
            })?;
            drop(progress);
            let s = &report.summary;
            println!(
                "{} frames at {}x{} on {}{}: {:.1} ms/frame average ({:.1} fps), median {:.1}, max {:.1}",
                s.frames,
                size[0],
                size[1],
                report.device,
                if stress {
                    " (stress)"
                } else if descent {
                    " (descent)"
                } else {
                    ""
                },
                s.frame_ms_mean,
                s.average_fps,
                s.frame_ms_median,
                s.frame_ms_max
            );
            println!(
                "  patches: {:.1} visible, {:.2} new per frame (max {}); samples {:.0} per frame (max {}); \
                 {:.0} terrain triangles per frame",
                s.average_visible_patches,
                s.average_new_patches,
                s.max_new_patches,
                s.average_samples,
                s.max_samples,
                s.triangles_mean
            );
            println!(
                "  memory: max {:.1} MB ({:.1} MB patch textures, {} of {} patches resident; {:.2} MB samples)",
                s.max_memory_bytes as f64 / 1e6,
                s.max_patch_texture_bytes as f64 / 1e6,
                s.max_resident_patches,
                s.resident_patch_budget,
                s.max_temporary_sample_bytes as f64 / 1e6
            );
            println!(
                "  deepest level {}; peak memory {:.1} MB; frame ms median {:.1}, max after {} warm-up frames {:.1}; \
                 at most {} patches made in a frame; {} hole pixels in {} checked frames",
                s.deepest_level,
                s.peak_memory_bytes as f64 / 1e6,
                s.frame_ms_median,
                bench::flight::WARMUP_FRAMES,
                s.frame_ms_max_after_warmup,
                s.max_generated_patches,
                s.hole_pixels,
                s.hole_checked_frames
            );
            println!("  gpu ms per frame: {:?}", s.average_gpu_ms);
            println!("  cpu ms per frame: {:?}", s.average_cpu_ms);
            if !s.fragments_per_pixel.is_empty() {
                println!("  fragments shaded per pixel: {:?}", s.fragments_per_pixel);
            }
            if s.kernel_frames > 0 {
                println!(
                    "  kernel over {} frames, average ms: {:?}",
                    s.kernel_frames, s.kernel_average_ms
                );
                println!("  kernel ratios: {:?}", s.kernel_ratios);
            }
            println!("  frame ms by water mode: {:?}", s.water_mode_frame_ms);
            check_validation(&ctx)?;
            if let Some(path) = csv {
                riverplanet::export::files::write_bytes(
                    &path,
                    bench::flight::to_csv(&report).as_bytes(),
                )?;
            }
            let mut report = report;
            if summary_only {
                report.frames.clear();
                report.water_mode_frames.clear();
            }
            write_json(&json, &report)?;
            Ok(())
        }
    }
}
