//! The viewer's camera paths (beyond the thesis): with `--record FILE` every frame's camera, written when the
//! viewer closes; and bookmarks, B appending the current camera to `bookmarks.json` in the screenshot folder and
//! 1 to 9 flying back to one. Both are camera paths (`runtime::camera_path`) that `render --path` and
//! `bench flight --path` replay.

use std::{path::PathBuf, time::Instant};

use glam::DVec3;

use super::viewer_camera::{CameraMode, ViewerCamera};
use crate::runtime::camera_path::{CameraPath, PathFrame};

/// The recording and the bookmarks of one viewer run.
pub struct ViewerPaths {
    record: Option<(PathBuf, CameraPath)>,
    bookmarks_file: PathBuf,
    bookmarks: CameraPath,
    start: Instant,
}

impl ViewerPaths {
    /// Recording into `record` if given; bookmarks kept in `bookmarks_file`, starting with the ones it holds.
    pub fn new(record: Option<PathBuf>, bookmarks_file: PathBuf, seed: u32) -> Self {
        let bookmarks = CameraPath::load(&bookmarks_file).unwrap_or(CameraPath {
            seed,
            frames: Vec::new(),
        });
        let empty = CameraPath {
            seed,
            frames: Vec::new(),
        };
        Self {
            record: record.map(|path| (path, empty)),
            bookmarks_file,
            bookmarks,
            start: Instant::now(),
        }
    }

    fn frame(&self, camera: &ViewerCamera, altitude: f64) -> PathFrame {
        let time = self.start.elapsed().as_secs_f64();
        PathFrame::new(time, camera.position, camera.forward, camera.up, altitude)
    }

    /// Notes a drawn frame's camera when recording.
    pub fn record(&mut self, camera: &ViewerCamera, altitude: f64) {
        let frame = self.frame(camera, altitude);
        if let Some((_, path)) = &mut self.record {
            path.frames.push(frame);
        }
    }

    /// B: appends the camera to the bookmarks and saves them; returns its number (1-based).
    pub fn bookmark(&mut self, camera: &ViewerCamera, altitude: f64) -> Result<usize, String> {
        let frame = self.frame(camera, altitude);
        self.bookmarks.frames.push(frame);
        save(&self.bookmarks_file, &self.bookmarks)?;
        Ok(self.bookmarks.frames.len())
    }

    /// 1 to 9: bookmark `k` (1-based) as a viewer camera, in orbit mode from more than half a radius up.
    pub fn recall(&self, k: usize, radius: f64) -> Option<ViewerCamera> {
        let f = self.bookmarks.frames.get(k.checked_sub(1)?)?;
        let position = DVec3::from_array(f.position);
        let mode = if position.length() > 1.5 * radius {
            CameraMode::Orbit
        } else {
            CameraMode::Fly
        };
        let mut camera = ViewerCamera::new(position, position + DVec3::from_array(f.forward), mode);
        camera.up = DVec3::from_array(f.up);
        Some(camera)
    }

    /// Writes the recorded path (when recording); returns where.
    pub fn finish(&self) -> Result<Option<&PathBuf>, String> {
        match &self.record {
            Some((file, path)) => save(file, path).map(|()| Some(file)),
            None => Ok(None),
        }
    }
}

fn save(file: &std::path::Path, path: &CameraPath) -> Result<(), String> {
    if let Some(folder) = file.parent().filter(|f| !f.as_os_str().is_empty()) {
        std::fs::create_dir_all(folder).map_err(|e| format!("{}: {e}", folder.display()))?;
    }
    let text = serde_json::to_string_pretty(path).map_err(|e| e.to_string())?;
    crate::export::files::write_bytes(file, text.as_bytes()).map_err(|e| e.to_string())
}
