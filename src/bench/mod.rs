//! The experiments of Chapter 9: the kernel variants on identical input (Tables 9.1 and 9.2) and scripted flights
//! with per-frame statistics (Figures 9.1-9.8). On lavapipe the "GPU" is the CPU: only ratios measured in the same
//! run mean anything, so every report records the device, `LP_NUM_THREADS`, `RAYON_NUM_THREADS` and the threads
//! rayon used.

pub mod flight;
pub mod holes;
pub mod kernel;
pub mod path;
pub mod plot;
pub mod report;
pub mod reuse;

use serde::Serialize;

/// The thread settings a measurement ran with.
#[derive(Clone, Debug, Serialize)]
pub struct Threads {
    /// `LP_NUM_THREADS` (lavapipe's rasterizer threads), where set.
    pub lp_num_threads: Option<String>,
    /// `RAYON_NUM_THREADS`, where set.
    pub rayon_num_threads: Option<String>,
    /// The threads rayon's pool has.
    pub rayon_threads_used: usize,
}

impl Threads {
    /// The settings of this process.
    pub fn current() -> Self {
        Self {
            lp_num_threads: std::env::var("LP_NUM_THREADS").ok(),
            rayon_num_threads: std::env::var("RAYON_NUM_THREADS").ok(),
            rayon_threads_used: rayon::current_num_threads(),
        }
    }
}

/// The median of `values` (0 for none).
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => v[n / 2],
        _ => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}
