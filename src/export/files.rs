//! Every output file goes through here: written to a temporary sibling and renamed into place, so a failed or
//! interrupted write leaves neither a partial file nor a destroyed old one; and output paths are checked before
//! any work starts, so a run is never thrown away for a typo.

use std::{
    fs,
    path::{Path, PathBuf},
};

use image::{ImageBuffer, ImageFormat, Pixel, PixelWithColorType};

use super::ExportError;

fn error(path: &Path, message: impl std::fmt::Display) -> ExportError {
    ExportError::Write {
        path: path.display().to_string(),
        message: message.to_string(),
    }
}

/// The temporary sibling of `path`: hidden, in the same folder (so the rename stays on one file system).
fn partial(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    path.with_file_name(format!(".{name}.partial-{}", std::process::id()))
}

/// Runs `write` on a temporary sibling of `path`, then renames it to `path`; on failure the temporary file is
/// removed and `path` is untouched.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), ExportError> {
    let temporary = partial(path);
    let result =
        write(&temporary).and_then(|()| fs::rename(&temporary, path).map_err(|e| e.to_string()));
    if result.is_err() {
        let _ = fs::remove_file(&temporary);
    }
    result.map_err(|message| error(path, message))
}

/// Writes `bytes` to `path` atomically.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), ExportError> {
    write_atomically(path, |t| fs::write(t, bytes).map_err(|e| e.to_string()))
}

/// Saves an image to `path` atomically, in the format its extension names.
pub fn save_image<P, C>(image: &ImageBuffer<P, C>, path: &Path) -> Result<(), ExportError>
where
    P: Pixel + PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
    C: std::ops::Deref<Target = [P::Subpixel]>,
{
    let format = ImageFormat::from_path(path).map_err(|e| error(path, e))?;
    write_atomically(path, |t| {
        image.save_with_format(t, format).map_err(|e| e.to_string())
    })
}

/// Checks before any work that `path` can be a folder to write into: an existing folder, or a new one whose
/// parent exists. `argument` names the option in the message.
pub fn check_folder(argument: &str, path: &Path) -> Result<(), String> {
    if path.exists() && !path.is_dir() {
        return Err(format!(
            "{argument} {} is a file; give a folder",
            path.display()
        ));
    }
    let parent = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !path.exists() && !parent.is_dir() {
        return Err(format!(
            "{argument} {}: the folder {} does not exist",
            path.display(),
            parent.display()
        ));
    }
    Ok(())
}

/// Checks before any work that `path` can be written: its folder exists (or `create` makes it) and, for
/// `png_only`, it names a PNG file. `argument` names the option in the message.
pub fn check_output(argument: &str, path: &Path, png_only: bool) -> Result<(), String> {
    let folder = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !folder.is_dir() {
        return Err(format!(
            "{argument} {}: the folder {} does not exist",
            path.display(),
            folder.display()
        ));
    }
    if path.is_dir() {
        return Err(format!(
            "{argument} {} is a folder; give a file name",
            path.display()
        ));
    }
    let png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if png_only && !png {
        return Err(format!(
            "{argument} {}: images are written as PNG; the name must end in .png",
            path.display()
        ));
    }
    Ok(())
}
