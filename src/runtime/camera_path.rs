//! A recorded camera path (beyond the thesis): what the viewer writes with `--record` (every frame) and with B
//! (bookmarks), and what `bench flight --path` and `render --path` replay. JSON: the seed, then per frame the time
//! since the start, the eye, the unit view direction and the screen's up (world coordinates, the planet's centre
//! at the origin), and the altitude above the drawn surface.

use std::path::Path;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::camera::Camera;

/// The viewer's vertical field of view, which every recorded frame was seen through.
pub const FOV_DEGREES: f64 = 60.0;

/// A recorded flight (`view --record`, bookmarks.json): the planet's seed and the camera of every frame.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct CameraPath {
    /// The seed of the planet it was recorded over.
    pub seed: u32,
    /// The camera of each frame, in order.
    pub frames: Vec<PathFrame>,
}

/// The most frames a camera path may have: an hour at 30 frames a second.
pub const MAX_FRAMES: usize = 108_000;
/// The largest camera-path file read: a generous 1 KB a frame.
const MAX_FILE_BYTES: u64 = MAX_FRAMES as u64 * 1024;

/// The camera of one recorded frame, in world units from the planet's centre.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct PathFrame {
    /// Seconds since the path started.
    pub time: f64,
    /// The eye.
    pub position: [f64; 3],
    /// The unit view direction.
    pub forward: [f64; 3],
    /// The screen's up.
    pub up: [f64; 3],
    /// Above the drawn surface (terrain or water) below the camera.
    pub altitude: f64,
}

impl PathFrame {
    /// A frame from vectors.
    pub fn new(time: f64, position: DVec3, forward: DVec3, up: DVec3, altitude: f64) -> Self {
        Self {
            time,
            position: position.to_array(),
            forward: forward.to_array(),
            up: up.to_array(),
            altitude,
        }
    }

    /// The camera of this frame for a viewport of `aspect`.
    pub fn camera(&self, aspect: f64) -> Camera {
        let position = DVec3::from_array(self.position);
        let near = super::camera::near_plane(self.altitude);
        let mut camera = Camera::look_at(
            position,
            position + DVec3::from_array(self.forward),
            FOV_DEGREES,
            aspect,
            near,
        );
        camera.up = DVec3::from_array(self.up);
        camera
    }
}

impl CameraPath {
    /// Reads a path, refusing one without frames or with a frame that is not finite, has no direction, or looks
    /// along its up (the message names the file and the frame).
    pub fn load(path: &Path) -> Result<Self, String> {
        let bytes = std::fs::metadata(path)
            .map_err(|e| format!("{}: {e}", path.display()))?
            .len();
        if bytes > MAX_FILE_BYTES {
            return Err(format!(
                "{}: {bytes} bytes, more than a path of {MAX_FRAMES} frames takes (at most {MAX_FILE_BYTES})",
                path.display()
            ));
        }
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let camera_path: Self = serde_json::from_str(&text)
            .map_err(|e| format!("{}: not a camera path: {e}", path.display()))?;
        if camera_path.frames.is_empty() {
            return Err(format!("{}: the path has no frames", path.display()));
        }
        if camera_path.frames.len() > MAX_FRAMES {
            return Err(format!(
                "{}: {} frames, at most {MAX_FRAMES} (an hour at 30 frames a second)",
                path.display(),
                camera_path.frames.len()
            ));
        }
        for (k, f) in camera_path.frames.iter().enumerate() {
            let [p, d, u] = [f.position, f.forward, f.up].map(DVec3::from_array);
            let finite = p.is_finite() && d.is_finite() && u.is_finite() && f.time.is_finite();
            if !finite
                || d.length() < 1e-9
                || u.length() < 1e-9
                || d.normalize().cross(u.normalize()).length() < 1e-6
            {
                return Err(format!(
                    "{}: frame {k} is not a camera (finite position, a direction, and an up not along it)",
                    path.display()
                ));
            }
        }
        Ok(camera_path)
    }
}
