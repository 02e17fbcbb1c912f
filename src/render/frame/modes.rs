//! What the viewer and the command line choose to see: how rivers are drawn and what the fragment shader shows.

use serde::Serialize;

/// How rivers are drawn (Section 8.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum WaterMode {
    /// The thesis's rule: water geometry where the mesh resolves the river, painted elsewhere.
    Auto,
    /// Always emit water triangles in river basins.
    Geometry,
    /// Always paint rivers in the fragment shader (sea water stays geometry).
    Painted,
}

impl crate::named::Named for WaterMode {
    const ALL: &'static [(&'static str, Self)] = &[
        ("auto", Self::Auto),
        ("geometry", Self::Geometry),
        ("painted", Self::Painted),
    ];
}

impl crate::named::Named for ViewMode {
    const ALL: &'static [(&'static str, Self)] = &[
        ("shaded", Self::Shaded),
        ("lod", Self::Lod),
        ("painted-red", Self::PaintedRed),
    ];
}

impl WaterMode {
    /// The mode after this one, in the viewer's cycle.
    pub fn next(self) -> Self {
        match self {
            WaterMode::Auto => WaterMode::Geometry,
            WaterMode::Geometry => WaterMode::Painted,
            WaterMode::Painted => WaterMode::Auto,
        }
    }
}

/// What the fragment shader shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ViewMode {
    /// The terrain and water as they look.
    Shaded,
    /// Patches tinted by level of detail.
    Lod,
    /// Painted rivers in red (as in the thesis's Fig. 9.9).
    PaintedRed,
}
