//! Height rasters for other tools (beyond the thesis): 32-bit float TIFF (uncompressed, which every reader
//! takes; GeoTIFF keys for longitude-latitude grids), 32-bit float OpenEXR (one channel Y, uncompressed, through
//! the `exr` crate; what film and terrain tools read) and 16-bit grey PNG. Their metadata (radius, units, sea
//! level, and the scale and offset that turn a pixel value into a height) goes into the TIFF's ImageDescription
//! as JSON and into the JSON the caller writes beside the files.

use std::{fs, io::BufWriter, path::Path};

use image::{ImageBuffer, Luma};
use rayon::prelude::*;
use serde_json::{json, Value};
use tiff::{
    encoder::{colortype::Gray32Float, TiffEncoder},
    tags::Tag,
};

use super::{files, ExportError};

/// The file format of a height raster.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RasterFormat {
    /// 32-bit float heights, as they are.
    Tiff,
    /// 32-bit float heights in channel Y.
    Exr,
    /// 16-bit grey: the raster's lowest to highest height mapped to 0..65535.
    Png,
}

impl RasterFormat {
    /// The format `--format` names, or what the names are.
    pub fn parse(text: &str) -> Result<Self, String> {
        match text {
            "tiff" | "tif" => Ok(Self::Tiff),
            "exr" => Ok(Self::Exr),
            "png" => Ok(Self::Png),
            _ => Err(format!(
                "'{text}' is not a height format: tiff or exr (32-bit float) or png (16-bit)"
            )),
        }
    }

    /// The name `--format` takes.
    pub fn name(self) -> &'static str {
        match self {
            Self::Tiff => "tiff",
            Self::Exr => "exr",
            Self::Png => "png",
        }
    }

    /// The file extension it writes.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Tiff => "tif",
            Self::Exr => "exr",
            Self::Png => "png",
        }
    }

    /// Whether `path` ends in one of this format's extensions.
    pub fn names(self, path: &Path) -> bool {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match self {
            Self::Tiff => matches!(extension.as_deref(), Some("tif" | "tiff")),
            Self::Exr | Self::Png => extension.as_deref() == Some(self.extension()),
        }
    }
}

/// A row-major grid of heights, row 0 at the top, and the range a PNG maps to 0..65535 (the grid's own, or a
/// wider one shared by several rasters, so that their values compare).
pub struct Raster<'a> {
    /// Pixels across.
    pub width: u32,
    /// Pixels down.
    pub height: u32,
    /// One height per pixel.
    pub heights: &'a [f32],
    /// The lowest and highest height a PNG maps to 0 and 65535.
    pub range: (f32, f32),
}

/// The lowest and highest of `heights`.
pub fn height_range(heights: &[f32]) -> (f32, f32) {
    heights
        .par_iter()
        .fold(
            || (f32::MAX, f32::MIN),
            |(lo, hi), &h| (lo.min(h), hi.max(h)),
        )
        .reduce(|| (f32::MAX, f32::MIN), |a, b| (a.0.min(b.0), a.1.max(b.1)))
}

/// Where a longitude-latitude raster lies: its top-left corner and pixel size in degrees, on a sphere of
/// `radius` (GeoTIFF: geographic model, pixels as areas, a user-defined sphere).
pub struct Georeference {
    /// Longitude of the west edge.
    pub west: f64,
    /// Latitude of the north edge.
    pub north: f64,
    /// Degrees a pixel spans along longitude and latitude.
    pub degrees_per_pixel: (f64, f64),
    /// The sphere's radius.
    pub radius: f64,
}

/// Writes `raster` to `path` atomically and returns its metadata: `metadata` plus `height_scale` and
/// `height_offset` (height = offset + scale x pixel value), `format`, `size` ([width, height]) and the heights' range.
pub fn write_raster(
    path: &Path,
    raster: &Raster,
    format: RasterFormat,
    metadata: &Value,
    geo: Option<&Georeference>,
) -> Result<Value, ExportError> {
    let (lo, hi) = raster.range;
    let (scale, offset) = match format {
        RasterFormat::Tiff | RasterFormat::Exr => (1.0, 0.0),
        RasterFormat::Png => ((hi - lo).max(0.0) as f64 / 65535.0, lo as f64),
    };
    let mut metadata = metadata.clone();
    metadata["format"] = json!(match format {
        RasterFormat::Tiff => "32-bit float TIFF",
        RasterFormat::Exr => "32-bit float OpenEXR, channel Y",
        RasterFormat::Png => "16-bit grey PNG",
    });
    metadata["size"] = json!([raster.width, raster.height]);
    metadata["height_scale"] = json!(scale);
    metadata["height_offset"] = json!(offset);
    let (min, max) = height_range(raster.heights);
    metadata["min_height"] = json!(min);
    metadata["max_height"] = json!(max);
    match format {
        RasterFormat::Tiff => write_tiff(path, raster, &metadata.to_string(), geo)?,
        RasterFormat::Exr => write_exr(path, raster, &metadata.to_string())?,
        RasterFormat::Png => write_png(path, raster, scale, offset)?,
    }
    Ok(metadata)
}

fn write_tiff(
    path: &Path,
    raster: &Raster,
    description: &str,
    geo: Option<&Georeference>,
) -> Result<(), ExportError> {
    files::write_atomically(path, |temporary| {
        let file = fs::File::create(temporary).map_err(|e| e.to_string())?;
        let mut writer = BufWriter::new(file);
        let mut tiff = TiffEncoder::new(&mut writer).map_err(|e| e.to_string())?;
        let mut image = tiff
            .new_image::<Gray32Float>(raster.width, raster.height)
            .map_err(|e| e.to_string())?;
        write_tags(image.encoder(), description, geo).map_err(|e| e.to_string())?;
        image
            .write_data(raster.heights)
            .map_err(|e| e.to_string())?;
        std::io::Write::flush(&mut writer).map_err(|e| e.to_string())
    })
}

fn write_tags<W: std::io::Write + std::io::Seek, K: tiff::encoder::TiffKind>(
    directory: &mut tiff::encoder::DirectoryEncoder<W, K>,
    description: &str,
    geo: Option<&Georeference>,
) -> tiff::TiffResult<()> {
    directory.write_tag(Tag::ImageDescription, description)?;
    directory.write_tag(Tag::Software, "riverplanet")?;
    match geo {
        Some(g) => write_geokeys(directory, g),
        None => Ok(()),
    }
}

/// GeoTIFF 1.1 keys (OGC 19-008): a geographic model in degrees on a user-defined sphere of the planet's radius
/// (in metres by the keys; the configuration's units in fact), pixels as areas, tied at the top-left corner.
fn write_geokeys<W: std::io::Write + std::io::Seek, K: tiff::encoder::TiffKind>(
    directory: &mut tiff::encoder::DirectoryEncoder<W, K>,
    g: &Georeference,
) -> tiff::TiffResult<()> {
    const USER_DEFINED: u16 = 32767;
    let citation = "riverplanet sphere|";
    // (key, location tag (0: the value itself), count, value or index)
    let keys: [[u16; 4]; 10] = [
        [1024, 0, 1, 2],                         // GTModelTypeGeoKey: geographic
        [1025, 0, 1, 1],                         // GTRasterTypeGeoKey: pixel is area
        [2048, 0, 1, USER_DEFINED],              // GeographicTypeGeoKey
        [2049, 34737, citation.len() as u16, 0], // GeogCitationGeoKey
        [2050, 0, 1, USER_DEFINED],              // GeogGeodeticDatumGeoKey
        [2052, 0, 1, 9001],                      // GeogLinearUnitsGeoKey: metre
        [2054, 0, 1, 9102],                      // GeogAngularUnitsGeoKey: degree
        [2056, 0, 1, USER_DEFINED],              // GeogEllipsoidGeoKey
        [2057, 34736, 1, 0],                     // GeogSemiMajorAxisGeoKey
        [2058, 34736, 1, 1],                     // GeogSemiMinorAxisGeoKey
    ];
    let mut directory_keys = vec![1, 1, 0, keys.len() as u16];
    directory_keys.extend(keys.iter().flatten());
    directory.write_tag(Tag::GeoKeyDirectoryTag, &directory_keys[..])?;
    directory.write_tag(Tag::GeoDoubleParamsTag, &[g.radius, g.radius][..])?;
    directory.write_tag(Tag::GeoAsciiParamsTag, citation)?;
    let (dx, dy) = g.degrees_per_pixel;
    directory.write_tag(Tag::ModelPixelScaleTag, &[dx, dy, 0.0][..])?;
    directory.write_tag(
        Tag::ModelTiepointTag,
        &[0.0, 0.0, 0.0, g.west, g.north, 0.0][..],
    )
}

/// One uncompressed scan-line part, channel Y, with the metadata as the text attribute `riverplanet`.
fn write_exr(path: &Path, raster: &Raster, description: &str) -> Result<(), ExportError> {
    use exr::prelude::*;
    let size = (raster.width as usize, raster.height as usize);
    let mut attributes = LayerAttributes::named("height");
    attributes.other.insert(
        Text::from("riverplanet"),
        AttributeValue::Text(Text::from(description)),
    );
    let channel = AnyChannel::new("Y", FlatSamples::F32(raster.heights.to_vec()));
    let layer = Layer::new(
        size,
        attributes,
        Encoding::UNCOMPRESSED,
        AnyChannels::sort(vec![channel].into()),
    );
    files::write_atomically(path, |temporary| {
        Image::from_layer(layer)
            .write()
            .to_file(temporary)
            .map_err(|e| e.to_string())
    })
}

fn write_png(path: &Path, raster: &Raster, scale: f64, offset: f64) -> Result<(), ExportError> {
    let image: ImageBuffer<Luma<u16>, Vec<u16>> =
        ImageBuffer::from_fn(raster.width, raster.height, |x, y| {
            let h = raster.heights[(y * raster.width + x) as usize] as f64;
            let value = if scale > 0.0 {
                (h - offset) / scale
            } else {
                0.0
            };
            Luma([value.round().clamp(0.0, 65535.0) as u16])
        });
    files::save_image(&image, path)
}
