//! `riverplanet export faces` and `export equirect` (beyond the thesis): the terrain with the rivers carved in
//! ([`super::carved`]) as six cube-face rasters or one longitude-latitude raster of the whole planet, with the
//! metadata other tools need to place and scale them.

use std::path::Path;

use rayon::prelude::*;
use serde_json::{json, Value};

use super::{
    carved::height_towards,
    files,
    raster::{height_range, write_raster, Georeference, Raster, RasterFormat},
    region::Region,
    ExportError,
};
use crate::planet::{
    cube::{cube_point, FACES, FACE_AXES},
    heights::FaceLattice,
    Planet,
};

/// What every height export says about its planet and its values; `carved`: whether the rivers are carved in
/// (`export`) or the heights are the base terrain (`generate`).
pub fn planet_metadata(planet: &Planet, seed: u32, level: u32, carved: bool) -> Value {
    let heights = if carved {
        "above the sphere of `radius`; river beds carved in as the renderer draws them (Section 8.2: the \
         kernel's river terrain blended into the base heights)"
    } else {
        "above the sphere of `radius`; the base terrain, no rivers carved in (riverplanet export faces carves them)"
    };
    json!({
        "generator": "riverplanet export",
        "seed": seed,
        "level": level,
        "radius": planet.radius,
        "units": "the configuration's length unit, the radius's (metres in config/earth.xml)",
        "heights": heights,
        "sea_level": planet.sea_level,
    })
}

/// Writes `dir/face{0..5}.{tif,png}` (pixel (i, j) of face f: lattice point (i, j), the direction of cube
/// point u = -1 + i step, v = -1 + j step on that face; PNGs share one height range, so that their values
/// compare across seams) and `dir/layout.json`: `metadata`, the height range, and per face its file, size,
/// cube orientation (origin and the steps of x and y) and value scale. Returns the layout.
pub fn write_faces(
    lattice: &FaceLattice,
    format: RasterFormat,
    dir: &Path,
    metadata: &Value,
) -> Result<Value, ExportError> {
    let side = lattice.side();
    let step = 2.0 / lattice.cells as f64;
    let range = height_range(&lattice.data);
    let faces = (0..FACES)
        .into_par_iter()
        .map(|face| {
            let file = format!("face{face}.{}", format.extension());
            let heights = &lattice.data[face * side * side..(face + 1) * side * side];
            let raster = Raster {
                width: side as u32,
                height: side as u32,
                heights,
                range,
            };
            let written = write_raster(&dir.join(&file), &raster, format, metadata, None)?;
            let (_, a, b) = FACE_AXES[face];
            Ok(json!({
                "face": face,
                "file": file,
                "size": [side, side],
                "origin": cube_point(face, -1.0, -1.0).to_array(),
                "step_x": (a * step).to_array(),
                "step_y": (b * step).to_array(),
                "height_scale": written["height_scale"],
                "height_offset": written["height_offset"],
                "min_height": written["min_height"],
                "max_height": written["max_height"],
            }))
        })
        .collect::<Result<Vec<_>, ExportError>>()?;
    let mut layout = metadata.clone();
    layout["min_height"] = json!(range.0);
    layout["max_height"] = json!(range.1);
    layout["faces"] = json!(faces);
    let path = dir.join("layout.json");
    let text = serde_json::to_string_pretty(&layout).expect("JSON values serialise");
    files::write_bytes(&path, text.as_bytes())?;
    Ok(layout)
}

/// Writes the whole planet as a `width` x `height` longitude-latitude raster to `path` (pixel (x, y) covers
/// longitudes -180 + x 360 / width onwards and latitudes 90 - y 180 / height downwards, sampled at its centre,
/// bilinear between lattice points; GeoTIFF keys in a TIFF) and its metadata to `path` with extension `.json`.
/// Returns the metadata.
pub fn write_equirect(
    lattice: &FaceLattice,
    (width, height): (u32, u32),
    format: RasterFormat,
    path: &Path,
    metadata: &Value,
    radius: f64,
) -> Result<Value, ExportError> {
    let world = Region {
        west: -180.0,
        south: -90.0,
        east: 180.0,
        north: 90.0,
        size: (width, height),
    };
    let heights: Vec<f32> = (0..height * width)
        .into_par_iter()
        .map(|k| height_towards(lattice, world.direction(k % width, k / width)))
        .collect();
    let geo = world.georeference(radius);
    write_georeferenced(path, (width, height), &heights, format, metadata, &geo)
}

/// Writes a longitude-latitude raster (row 0 in the north) with its georeference, and its metadata to `path`
/// with extension `.json`. Returns the metadata.
pub fn write_georeferenced(
    path: &Path,
    (width, height): (u32, u32),
    heights: &[f32],
    format: RasterFormat,
    metadata: &Value,
    geo: &Georeference,
) -> Result<Value, ExportError> {
    let raster = Raster {
        width,
        height,
        heights,
        range: height_range(heights),
    };
    let mut metadata = write_raster(path, &raster, format, metadata, Some(geo))?;
    let (dx, dy) = geo.degrees_per_pixel;
    // Where the raster lies, for readers of a PNG or EXR (which carry no GeoTIFF tags): `<terrain-file>` reads it.
    metadata["bounds"] = json!([
        geo.west,
        geo.north - dy * height as f64,
        geo.west + dx * width as f64,
        geo.north
    ]);
    metadata["projection"] = json!(format!(
        "equirectangular: pixel (x, y) covers longitudes {} + x {dx} onwards (east positive, from +X towards -Z) \
         and latitudes {} - y {dy} downwards (north: +Y)",
        geo.west, geo.north
    ));
    let text = serde_json::to_string_pretty(&metadata).expect("JSON values serialise");
    files::write_bytes(&path.with_extension("json"), text.as_bytes())?;
    Ok(metadata)
}
