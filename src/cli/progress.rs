//! Progress of a long command on a terminal (issue "Your own terrain, your own program"): what it is doing, for how
//! long, and where it counts its steps, how long is left. Nothing when standard error is not a terminal (piped or
//! captured), so scripts and logs see only the results.

use std::{borrow::Cow, io::IsTerminal, time::Duration};

use indicatif::{ProgressBar, ProgressStyle};

pub struct Progress(Option<ProgressBar>);

/// The planet and its rivers of `config` and `seed`, each stage shown on the terminal while it runs.
pub fn build_world(
    config: &riverplanet::config::Config,
    seed: u32,
) -> Result<riverplanet::world::World, riverplanet::planet::PlanetError> {
    let progress = Progress::start("planet");
    riverplanet::world::World::build_reporting(config, seed, |stage| {
        progress.stage(stage.to_string())
    })
}

impl Progress {
    /// A spinner showing `message` and the time since it started.
    pub fn start(message: impl Into<Cow<'static, str>>) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::new_spinner();
            bar.enable_steady_tick(Duration::from_millis(100));
            bar
        });
        let progress = Self(bar);
        progress.stage(message);
        progress
    }

    /// A stage of the command whose steps are not counted: what it does, and for how long.
    pub fn stage(&self, message: impl Into<Cow<'static, str>>) {
        self.style("{spinner} {msg} ({elapsed})");
        self.say(message);
    }

    /// A stage of `total` steps, with an estimate of the time left.
    pub fn count(&self, message: impl Into<Cow<'static, str>>, total: u64) {
        self.style("{msg} {bar:30} {pos}/{len} ({elapsed}, about {eta} left)");
        if let Some(bar) = &self.0 {
            bar.set_length(total);
            bar.set_position(0);
        }
        self.say(message);
    }

    /// Says what the command does now, within its stage.
    pub fn say(&self, message: impl Into<Cow<'static, str>>) {
        if let Some(bar) = &self.0 {
            bar.set_message(message);
        }
    }

    /// One more step counted (from any thread).
    pub fn step(&self) {
        if let Some(bar) = &self.0 {
            bar.inc(1);
        }
    }

    /// Sets the steps counted so far.
    pub fn set(&self, done: u64) {
        if let Some(bar) = &self.0 {
            bar.set_position(done);
        }
    }

    fn style(&self, template: &str) {
        if let Some(bar) = &self.0 {
            bar.set_style(ProgressStyle::with_template(template).expect("a valid template"));
        }
    }
}

impl Drop for Progress {
    /// The line is cleared when the command ends, however it ends.
    fn drop(&mut self) {
        if let Some(bar) = &self.0 {
            bar.finish_and_clear();
        }
    }
}
