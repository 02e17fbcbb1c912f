//! Criterion benchmark of a patch's river samples (Sections 6.3-6.4), the CPU work of every new patch with rivers
//! in a frame: on config/earth.xml (seed 31, the seed of the descent benchmark), every patch of level 4 and the
//! patches of levels 6-24 a third of the way up 40 rivers.

use criterion::{criterion_group, criterion_main, Criterion};
use riverplanet::{
    config::Config,
    planet::cube::PatchId,
    river::samples::{patch_samples, PatchFrame},
    world::World,
};

fn samples(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/earth.xml");
    let config = Config::load(path.as_ref()).expect("config/earth.xml");
    let world = World::build(&config, 31).expect("Earth's world");
    let (radius, n) = (world.planet.radius, config.rendering.vertices);
    let frames = |patches: Vec<PatchId>| -> Vec<PatchFrame> {
        patches
            .into_iter()
            .map(|p| PatchFrame::new(p, radius, n))
            .collect()
    };
    let level4 = frames(
        (0..6u8)
            .flat_map(|face| {
                (0..16u32 * 16).map(move |k| PatchId {
                    face,
                    level: 4,
                    x: k % 16,
                    y: k / 16,
                })
            })
            .collect(),
    );
    let deep = frames(
        world
            .network
            .systems
            .iter()
            .take(40)
            .flat_map(|s| {
                let d = s.mouth.lerp(s.source, 0.3).normalize();
                (6..=24u8)
                    .step_by(2)
                    .map(move |level| PatchId::containing(d, level))
            })
            .collect(),
    );
    let mut group = c.benchmark_group("patch samples");
    group.sample_size(10);
    for (name, frames) in [
        ("earth level 4 (1536 patches)", &level4),
        ("earth levels 6-24 (400 patches)", &deep),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                frames
                    .iter()
                    .map(|f| patch_samples(&world.network, f).samples.len())
                    .sum::<usize>()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, samples);
criterion_main!(benches);
