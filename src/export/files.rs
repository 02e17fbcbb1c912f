//! Every output file goes through here: written to a temporary sibling and renamed into place, so a failed or
//! interrupted write leaves neither a partial file nor a destroyed old one (a stopped program removes its temporary
//! files, src/interrupt.rs; the next write removes those a killed one left); and output paths are checked before any
//! work starts, so a run is never thrown away for a typo.

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
    remove_leftovers(path);
    let temporary = partial(path);
    in_progress().push(temporary.clone());
    let result =
        write(&temporary).and_then(|()| fs::rename(&temporary, path).map_err(|e| e.to_string()));
    if result.is_err() {
        let _ = fs::remove_file(&temporary);
    }
    in_progress().retain(|p| *p != temporary);
    result.map_err(|message| error(path, message))
}

/// The temporary files being written now, for [`remove_partial_files`].
fn in_progress() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    static FILES: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());
    FILES.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes the temporary files being written (src/interrupt.rs, when the program is stopped); how many.
pub fn remove_partial_files() -> usize {
    in_progress()
        .drain(..)
        .filter(|p| match p.is_dir() {
            true => fs::remove_dir_all(p).is_ok(),
            false => fs::remove_file(p).is_ok(),
        })
        .count()
}

/// Files written as one set into a folder (the six faces and layout.json; generate's faces, stats and rivers):
/// written into a hidden sibling folder, which [`OutputSet::commit`] swaps with the folder in one atomic rename
/// (Linux's RENAME_EXCHANGE), so a run that fails, is stopped or killed, or runs out of disk leaves the old set
/// whole. Files in the folder that the new set does not write are kept. Dropped uncommitted, the new set is removed.
pub struct OutputSet {
    folder: PathBuf,
    staging: PathBuf,
    committed: bool,
}

impl OutputSet {
    /// Starts a set for `folder` (whose parent exists: `check_folder`), removing what killed runs left beside it.
    pub fn begin(folder: &Path) -> Result<Self, ExportError> {
        remove_leftovers(folder);
        let staging = partial(folder);
        let _ = fs::remove_dir_all(&staging);
        fs::create_dir(&staging).map_err(|e| error(&staging, e))?;
        in_progress().push(staging.clone());
        Ok(Self {
            folder: folder.to_path_buf(),
            staging,
            committed: false,
        })
    }

    /// Where the set's files are written until it is committed.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Puts the set in place of the folder at once, keeps the folder's files that the set does not replace, and
    /// removes the old set.
    pub fn commit(mut self) -> Result<(), ExportError> {
        let fail = |e: std::io::Error| error(&self.folder, e);
        if !self.folder.exists() {
            fs::rename(&self.staging, &self.folder).map_err(fail)?;
        } else {
            exchange(&self.staging, &self.folder).map_err(fail)?;
            // `staging` now holds the old folder: keep what the new set does not write.
            for entry in fs::read_dir(&self.staging).map_err(fail)?.flatten() {
                let target = self.folder.join(entry.file_name());
                if !target.exists() && !left_by_a_dead_run(&entry.file_name().to_string_lossy()) {
                    fs::rename(entry.path(), target).map_err(fail)?;
                }
            }
            let _ = fs::remove_dir_all(&self.staging);
        }
        in_progress().retain(|p| *p != self.staging);
        self.committed = true;
        Ok(())
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_dir_all(&self.staging);
            in_progress().retain(|p| *p != self.staging);
        }
    }
}

/// Swaps two paths in one step where the system can (Linux), else in two renames through a third name.
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::ffi::OsStrExt;
        let (ca, cb) = (
            std::ffi::CString::new(a.as_os_str().as_bytes())?,
            std::ffi::CString::new(b.as_os_str().as_bytes())?,
        );
        // SAFETY: two valid C strings; RENAME_EXCHANGE swaps the two existing paths atomically.
        let done = unsafe {
            libc::renameat2(
                libc::AT_FDCWD,
                ca.as_ptr(),
                libc::AT_FDCWD,
                cb.as_ptr(),
                libc::RENAME_EXCHANGE,
            )
        };
        if done == 0 {
            return Ok(());
        }
    }
    let aside = b.with_file_name(format!(
        ".{}.old-{}",
        b.file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
        std::process::id()
    ));
    fs::rename(b, &aside)?;
    fs::rename(a, b)?;
    fs::rename(&aside, a)
}

/// Removes the temporary siblings of `path` that killed runs left (SIGKILL, a power cut): those whose process is
/// gone.
fn remove_leftovers(path: &Path) {
    let (Some(folder), Some(name)) = (path.parent(), path.file_name()) else {
        return;
    };
    let folder = if folder.as_os_str().is_empty() {
        Path::new(".")
    } else {
        folder
    };
    let prefix = format!(".{}.partial-", name.to_string_lossy());
    let Ok(entries) = fs::read_dir(folder) else {
        return;
    };
    for entry in entries.flatten() {
        let file = entry.file_name().to_string_lossy().into_owned();
        if file.starts_with(&prefix) && left_by_a_dead_run(&file) {
            let path = entry.path();
            let _ = match path.is_dir() {
                true => fs::remove_dir_all(path),
                false => fs::remove_file(path),
            };
        }
    }
}

/// Whether `file` is a temporary file or set (`.NAME.partial-PID`) whose process is gone.
fn left_by_a_dead_run(file: &str) -> bool {
    let pid = file
        .strip_prefix('.')
        .and_then(|f| f.rsplit_once(".partial-"))
        .and_then(|(_, pid)| pid.parse::<i32>().ok());
    pid.is_some_and(|pid| pid != std::process::id() as i32 && !alive(pid))
}

/// Whether process `pid` exists.
#[cfg(unix)]
fn alive(pid: i32) -> bool {
    // SAFETY: signal 0 only checks that the process exists.
    unsafe {
        libc::kill(pid, 0) == 0
            || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
    }
}

#[cfg(not(unix))]
fn alive(_: i32) -> bool {
    true
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

#[cfg(test)]
mod tests {
    use super::*;

    /// What the stopping thread does mid-write: the temporary file goes, the old file stays, nothing is left listed.
    #[test]
    fn a_stop_mid_write_removes_the_temporary_file_and_keeps_the_old_one() {
        let dir = std::env::temp_dir().join(format!("riverplanet-files-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let path = dir.join("face0.tif");
        fs::write(&path, b"old").unwrap();
        let mut removed = 0;
        let result = write_atomically(&path, |temporary| {
            fs::write(temporary, b"half").unwrap();
            removed = remove_partial_files();
            assert!(!temporary.exists());
            Err("stopped".into())
        });
        assert!(result.is_err());
        // At least ours (another test may be writing at the same time).
        assert!(removed >= 1);
        assert_eq!(fs::read(&path).unwrap(), b"old");
        let left: Vec<_> = fs::read_dir(&dir)
            .unwrap()
            .flatten()
            .map(|e| e.file_name())
            .collect();
        assert_eq!(left.len(), 1, "{left:?}");
    }
}
