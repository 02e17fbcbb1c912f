//! A region as a binary glTF 2.0 mesh (beyond the thesis): the terrain (river beds carved in) and the water
//! surface as two meshes over the region's sample grid, with vertex normals, in a local frame whose origin is the
//! sea-level sphere below the region's centre: +X east, +Y up, -Z north (glTF's right-handed, Y-up frame), in the
//! configuration's length unit, curvature kept. The water mesh holds the cells with a corner in a river's basin or
//! below sea level, at the water heights, as the geometry shader spawns water (Section 8.4) in the geometry water
//! mode; near a river mouth a cell takes the river's water height where the renderer takes sea level.
//! The document is built with the `gltf-json` crate; the GLB container (a 12-byte header and two chunks) here.

use std::{collections::BTreeMap, path::Path};

use glam::{DVec3, Vec3};
use gltf_json::{
    self as json,
    validation::{Checked::Valid, USize64},
};

use super::{
    files,
    region::{Region, RegionSurface},
    ExportError,
};
use crate::planet::direction_at;

/// One mesh's vertices, normals and triangle indices.
struct Geometry {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    indices: Vec<u32>,
}

/// The local east-north-up frame at the region's centre.
struct LocalFrame {
    origin: DVec3,
    east: DVec3,
    north: DVec3,
    up: DVec3,
}

impl LocalFrame {
    fn at(region: &Region, radius: f64) -> Self {
        let up = direction_at(
            0.5 * (region.west + region.east),
            0.5 * (region.south + region.north),
        );
        let pole = if up.y.abs() > 0.99 {
            DVec3::X
        } else {
            DVec3::Y
        };
        let east = pole.cross(up).normalize();
        Self {
            origin: up * radius,
            east,
            north: up.cross(east),
            up,
        }
    }

    /// glTF coordinates of a world point.
    fn place(&self, p: DVec3) -> Vec3 {
        let d = p - self.origin;
        Vec3::new(
            d.dot(self.east) as f32,
            d.dot(self.up) as f32,
            -d.dot(self.north) as f32,
        )
    }
}

/// The grid of `heights` (row by row from the north-west) as a mesh; with `cell_kept`, only the cells it keeps.
fn grid_geometry(
    region: &Region,
    frame: &LocalFrame,
    radius: f64,
    heights: &[f32],
    cell_kept: impl Fn(usize, usize, usize, usize) -> bool,
) -> Geometry {
    let (width, height) = (region.size.0 as usize, region.size.1 as usize);
    let positions: Vec<Vec3> = (0..width * height)
        .map(|k| {
            let d = region.direction((k % width) as u32, (k / width) as u32);
            frame.place(d * (radius + heights[k] as f64))
        })
        .collect();
    // Central differences (one-sided at the border) across the grid; rows run south, so east x south is up.
    let normals = (0..width * height)
        .map(|k| {
            let (x, y) = (k % width, k / width);
            let at = |x: usize, y: usize| positions[y * width + x];
            let east = at((x + 1).min(width - 1), y) - at(x.saturating_sub(1), y);
            let south = at(x, (y + 1).min(height - 1)) - at(x, y.saturating_sub(1));
            east.cross(-south).normalize_or(Vec3::Y)
        })
        .collect();
    let mut indices = Vec::new();
    for y in 0..height - 1 {
        for x in 0..width - 1 {
            let (a, b) = (y * width + x, y * width + x + 1);
            let (c, d) = (a + width, b + width);
            if cell_kept(a, b, c, d) {
                // Counter-clockwise seen from above (+Y).
                indices.extend([a, c, b, b, c, d].map(|i| i as u32));
            }
        }
    }
    Geometry {
        positions,
        normals,
        indices,
    }
}

/// Writes `surface` of `region` to `path` as binary glTF: mesh "terrain" and mesh "water" (dry cells left out;
/// no water mesh where the region has no water), `metadata` as the asset's extras. Returns the triangle counts
/// of both.
pub fn write_glb(
    path: &Path,
    region: &Region,
    surface: &RegionSurface,
    (radius, sea_level): (f64, f32),
    metadata: &serde_json::Value,
) -> Result<(usize, usize), ExportError> {
    let frame = LocalFrame::at(region, radius);
    let terrain = grid_geometry(region, &frame, radius, &surface.terrain, |_, _, _, _| true);
    // As the geometry shader decides (Section 8.4, water mode geometry): a cell has water where a corner lies in a
    // river's basin or below sea level.
    let wet = |k: usize| surface.basin[k] > 0.0 || surface.terrain[k] < sea_level;
    let water = grid_geometry(region, &frame, radius, &surface.water, |a, b, c, d| {
        wet(a) || wet(b) || wet(c) || wet(d)
    });
    let mut root = json::Root::default();
    let mut bin = Vec::new();
    let materials = [
        (
            "terrain",
            [0.36, 0.42, 0.26, 1.0],
            json::material::AlphaMode::Opaque,
        ),
        (
            "water",
            [0.10, 0.30, 0.50, 0.8],
            json::material::AlphaMode::Blend,
        ),
    ];
    let mut nodes = Vec::new();
    // A mesh without triangles is left out (glTF accessors hold at least one element).
    for (geometry, (name, colour, alpha)) in [&terrain, &water]
        .into_iter()
        .zip(materials)
        .filter(|(g, _)| !g.indices.is_empty())
    {
        let material = root.push(json::Material {
            name: Some(name.to_string()),
            alpha_mode: Valid(alpha),
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor(colour),
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(if name == "water" {
                    0.1
                } else {
                    0.9
                }),
                ..Default::default()
            },
            ..Default::default()
        });
        let positions = push_vec3s(&mut root, &mut bin, &geometry.positions, true);
        let normals = push_vec3s(&mut root, &mut bin, &geometry.normals, false);
        let indices = push_indices(&mut root, &mut bin, &geometry.indices);
        let primitive = json::mesh::Primitive {
            attributes: BTreeMap::from([
                (Valid(json::mesh::Semantic::Positions), positions),
                (Valid(json::mesh::Semantic::Normals), normals),
            ]),
            extensions: Default::default(),
            extras: Default::default(),
            indices: Some(indices),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        };
        let mesh = root.push(json::Mesh {
            extensions: Default::default(),
            extras: Default::default(),
            name: Some(name.to_string()),
            primitives: vec![primitive],
            weights: None,
        });
        nodes.push(root.push(json::Node {
            mesh: Some(mesh),
            name: Some(name.to_string()),
            ..Default::default()
        }));
    }
    root.push(json::Buffer {
        byte_length: USize64::from(bin.len()),
        extensions: Default::default(),
        extras: Default::default(),
        name: None,
        uri: None,
    });
    let scene = root.push(json::Scene {
        extensions: Default::default(),
        extras: Default::default(),
        name: Some("riverplanet region".to_string()),
        nodes,
    });
    root.scene = Some(scene);
    root.asset.generator = Some("riverplanet export region".to_string());
    root.asset.extras =
        Some(serde_json::value::to_raw_value(metadata).expect("JSON values serialise"));
    let document = root.to_vec().expect("glTF documents serialise");
    files::write_bytes(path, &glb(document, bin))?;
    Ok((terrain.indices.len() / 3, water.indices.len() / 3))
}

/// Appends `values` to the binary chunk as an accessor of 3-vectors (with their bounds for positions).
fn push_vec3s(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    values: &[Vec3],
    bounds: bool,
) -> json::Index<json::Accessor> {
    let (min, max) = values.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), v| (lo.min(*v), hi.max(*v)),
    );
    let view = push_view(
        root,
        bin,
        bytemuck::cast_slice(values),
        json::buffer::Target::ArrayBuffer,
    );
    root.push(json::Accessor {
        buffer_view: Some(view),
        byte_offset: None,
        count: USize64::from(values.len()),
        component_type: Valid(json::accessor::GenericComponentType(
            json::accessor::ComponentType::F32,
        )),
        extensions: Default::default(),
        extras: Default::default(),
        type_: Valid(json::accessor::Type::Vec3),
        min: bounds.then(|| json::Value::from(min.to_array().to_vec())),
        max: bounds.then(|| json::Value::from(max.to_array().to_vec())),
        name: None,
        normalized: false,
        sparse: None,
    })
}

fn push_indices(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    indices: &[u32],
) -> json::Index<json::Accessor> {
    let view = push_view(
        root,
        bin,
        bytemuck::cast_slice(indices),
        json::buffer::Target::ElementArrayBuffer,
    );
    root.push(json::Accessor {
        buffer_view: Some(view),
        byte_offset: None,
        count: USize64::from(indices.len()),
        component_type: Valid(json::accessor::GenericComponentType(
            json::accessor::ComponentType::U32,
        )),
        extensions: Default::default(),
        extras: Default::default(),
        type_: Valid(json::accessor::Type::Scalar),
        min: None,
        max: None,
        name: None,
        normalized: false,
        sparse: None,
    })
}

/// Appends `bytes` (padded to four) to the binary chunk as a buffer view of buffer 0.
fn push_view(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    bytes: &[u8],
    target: json::buffer::Target,
) -> json::Index<json::buffer::View> {
    let offset = bin.len();
    bin.extend_from_slice(bytes);
    bin.resize(bin.len().next_multiple_of(4), 0);
    root.push(json::buffer::View {
        buffer: json::Index::new(0),
        byte_length: USize64::from(bytes.len()),
        byte_offset: Some(USize64::from(offset)),
        byte_stride: None,
        extensions: Default::default(),
        extras: Default::default(),
        name: None,
        target: Some(Valid(target)),
    })
}

/// The GLB container (glTF 2.0, section 4.4): header, JSON chunk padded with spaces, binary chunk padded with
/// zeros.
fn glb(mut document: Vec<u8>, mut bin: Vec<u8>) -> Vec<u8> {
    document.resize(document.len().next_multiple_of(4), b' ');
    bin.resize(bin.len().next_multiple_of(4), 0);
    let length = 12 + 8 + document.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(length);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(length as u32).to_le_bytes());
    for (chunk, kind) in [(&document, b"JSON"), (&bin, b"BIN\0")] {
        out.extend_from_slice(&(chunk.len() as u32).to_le_bytes());
        out.extend_from_slice(kind);
        out.extend_from_slice(chunk);
    }
    out
}
