//! Files: NumPy `.npy` arrays, JSON sidecars, and atomic writes.
//!
//! Every output goes through [`atomic_write`]: the data is written to a hidden temporary
//! file beside the target and renamed over it only once complete, so an interrupted run
//! never leaves a truncated file; outputs that must appear together (a table and its field
//! files) go through an [`OutputBatch`], renamed into place only once all are written.
//! Outputs are never overwritten unless `force` is set. [`npy_shape`] reads a `.npy`
//! file's shape without its data (to check memory before reading).
//! Inputs are validated on reading: `.npy` must hold float64 (C or Fortran order), have the
//! expected number of dimensions, and contain finite values only.

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

use ndarray::{Array1, Array2, ArrayD, ArrayView2, Ix1, Ix2};
use ndarray_npy::npy::header::Header;
use ndarray_npy::{ReadNpyError, ReadNpyExt, WriteNpyExt};
use serde::Serialize;

use crate::{ensure_finite, Error, Result};

/// Fails with [`Error::OutputExists`] when `path` exists and `force` is false.
///
/// Call it for every output *before* starting work, so that a refusal loses nothing.
pub fn ensure_new_output(path: &Path, force: bool) -> Result<()> {
    if !force && path.exists() {
        return Err(Error::OutputExists(path.to_path_buf()));
    }
    Ok(())
}

/// The sidecar path of an array file: `surface.npy` → `surface.npy.json`.
pub fn sidecar_path(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_os_string();
    name.push(".json");
    PathBuf::from(name)
}

fn temp_path(path: &Path) -> PathBuf {
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let tmp = format!(".{file_name}.{}.tmp", std::process::id());
    path.with_file_name(tmp)
}

/// Writes `path` atomically: `write` fills a temporary file in the same folder, which is
/// flushed, synced and renamed over `path`. On any error the temporary file is removed and
/// `path` is left as it was.
pub fn atomic_write<F>(path: &Path, force: bool, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    ensure_new_output(path, force)?;
    let tmp = write_temp(path, write)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::io(path, e)
    })
}

/// Fills, flushes and syncs the temporary file of `path` (see [`atomic_write`]) and returns
/// its name; removes it on any error.
fn write_temp<F>(path: &Path, write: F) -> Result<PathBuf>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    let tmp = temp_path(path);
    let result = (|| {
        let file = File::create(&tmp).map_err(|e| Error::io(&tmp, e))?;
        let mut writer = BufWriter::new(file);
        write(&mut writer)?;
        writer.flush().map_err(|e| Error::io(&tmp, e))?;
        writer.get_ref().sync_all().map_err(|e| Error::io(&tmp, e))
    })();
    match result {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// Outputs that appear together or not at all. Each is written to its temporary file
/// beside the target as soon as it is ready ([`OutputBatch::write`]: nothing waits in
/// memory), and [`OutputBatch::commit`] renames them all into place at the end. A batch
/// dropped without a commit (an error on the way) removes its temporary files and the
/// folders it created, so a failed run leaves nothing behind.
#[derive(Debug)]
pub struct OutputBatch {
    force: bool,
    /// `(temporary file, target, target existed before)`, in the order written.
    staged: Vec<(PathBuf, PathBuf, bool)>,
    /// Folders made by [`OutputBatch::create_dir_all`], outermost first.
    created_dirs: Vec<PathBuf>,
}

impl OutputBatch {
    /// An empty batch; `force` allows its outputs to replace existing files.
    pub fn new(force: bool) -> Self {
        OutputBatch {
            force,
            staged: Vec::new(),
            created_dirs: Vec::new(),
        }
    }

    /// Creates `dir` and its missing parents; they are removed again (if still empty) when
    /// the batch is dropped uncommitted.
    pub fn create_dir_all(&mut self, dir: &Path) -> Result<()> {
        let mut missing = Vec::new();
        let mut next = Some(dir);
        while let Some(d) = next.filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
            missing.push(d.to_path_buf());
            next = d.parent();
        }
        for d in missing.into_iter().rev() {
            std::fs::create_dir(&d).map_err(|e| Error::io(&d, e))?;
            self.created_dirs.push(d);
        }
        Ok(())
    }

    /// Writes the temporary file of `path` now (see [`atomic_write`] for `write`); `path`
    /// itself appears at [`OutputBatch::commit`]. Refuses an existing `path` unless forced.
    pub fn write<F>(&mut self, path: &Path, write: F) -> Result<()>
    where
        F: FnOnce(&mut BufWriter<File>) -> Result<()>,
    {
        ensure_new_output(path, self.force)?;
        if self.staged.iter().any(|(_, target, _)| target == path) {
            return Err(Error::invalid(
                "output",
                format!("{} is named twice", path.display()),
            ));
        }
        let existed = path.exists();
        let tmp = write_temp(path, write)?;
        self.staged.push((tmp, path.to_path_buf(), existed));
        Ok(())
    }

    /// [`OutputBatch::write`] of bytes.
    pub fn write_bytes(&mut self, path: &Path, bytes: &[u8]) -> Result<()> {
        self.write(path, |w| w.write_all(bytes).map_err(|e| Error::io(path, e)))
    }

    /// [`OutputBatch::write`] of a 2D float64 array as `.npy` (C order).
    pub fn write_npy_2d(&mut self, path: &Path, array: ArrayView2<'_, f64>) -> Result<()> {
        self.write(path, |w| {
            array.write_npy(w).map_err(|e| Error::BadArrayFile {
                path: path.to_path_buf(),
                reason: e.to_string(),
            })
        })
    }

    /// Renames every temporary file over its target, in the order written. Should a rename
    /// fail, the targets already renamed that did not exist before are removed again.
    pub fn commit(mut self) -> Result<()> {
        let staged = std::mem::take(&mut self.staged);
        for (i, (tmp, path, _)) in staged.iter().enumerate() {
            if let Err(e) = std::fs::rename(tmp, path) {
                for (_, done, existed) in &staged[..i] {
                    if !existed {
                        let _ = std::fs::remove_file(done);
                    }
                }
                for (tmp, _, _) in &staged[i..] {
                    let _ = std::fs::remove_file(tmp);
                }
                return Err(Error::io(path, e));
            }
        }
        self.created_dirs.clear();
        Ok(())
    }
}

impl Drop for OutputBatch {
    fn drop(&mut self) {
        for (tmp, _, _) in &self.staged {
            let _ = std::fs::remove_file(tmp);
        }
        for dir in self.created_dirs.iter().rev() {
            let _ = std::fs::remove_dir(dir); // only if empty
        }
    }
}

/// Writes bytes atomically (see [`atomic_write`]).
pub fn write_bytes(path: &Path, force: bool, bytes: &[u8]) -> Result<()> {
    atomic_write(path, force, |w| {
        w.write_all(bytes).map_err(|e| Error::io(path, e))
    })
}

/// Writes a value as pretty JSON, atomically.
pub fn write_json<T: Serialize>(path: &Path, force: bool, value: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(value).map_err(|e| Error::Metadata {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    write_bytes(path, force, format!("{text}\n").as_bytes())
}

fn write_npy_impl<A: WriteNpyExt>(path: &Path, force: bool, array: &A) -> Result<()> {
    atomic_write(path, force, |w| {
        array.write_npy(w).map_err(|e| Error::BadArrayFile {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })
    })
}

/// Writes a 2D float64 array as `.npy` (C order), atomically.
pub fn write_npy_2d(path: &Path, force: bool, array: &Array2<f64>) -> Result<()> {
    write_npy_impl(path, force, array)
}

/// Writes a 1D float64 array as `.npy`, atomically.
pub fn write_npy_1d(path: &Path, force: bool, array: &Array1<f64>) -> Result<()> {
    write_npy_impl(path, force, array)
}

/// Reads a float64 `.npy` of any dimension and checks that all values are finite.
pub fn read_npy(path: &Path) -> Result<ArrayD<f64>> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let array = ArrayD::<f64>::read_npy(BufReader::new(file)).map_err(|e| {
        let reason = match e {
            ReadNpyError::WrongDescriptor(d) => {
                format!("expected a float64 array, found dtype {d}")
            }
            other => format!("not a readable .npy array ({other})"),
        };
        Error::BadArrayFile {
            path: path.to_path_buf(),
            reason,
        }
    })?;
    if array.is_empty() {
        return Err(Error::BadArrayFile {
            path: path.to_path_buf(),
            reason: "the array is empty".into(),
        });
    }
    ensure_finite(&path.display().to_string(), array.iter())?;
    Ok(array)
}

fn wrong_shape(path: &Path, want: &str, shape: &[usize]) -> Error {
    Error::BadArrayFile {
        path: path.to_path_buf(),
        reason: format!("expected a {want} array, found shape {shape:?}"),
    }
}

/// Reads a 2D float64 `.npy` (a surface): finite values, at least 2×2.
pub fn read_npy_2d(path: &Path) -> Result<Array2<f64>> {
    let array = read_npy(path)?;
    let shape = array.shape().to_vec();
    let array = array
        .into_dimensionality::<Ix2>()
        .map_err(|_| wrong_shape(path, "2D (rows, cols)", &shape))?;
    if array.nrows() < 2 || array.ncols() < 2 {
        return Err(wrong_shape(path, "2D array of at least 2x2", &shape));
    }
    Ok(array.as_standard_layout().into_owned())
}

/// The shape of the array in a `.npy` file, from its header alone (the data is not read):
/// lets a caller check the memory a file will need before reading it.
pub fn npy_shape(path: &Path) -> Result<Vec<usize>> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let header =
        Header::from_reader(&mut BufReader::new(file)).map_err(|e| Error::BadArrayFile {
            path: path.to_path_buf(),
            reason: format!("not a readable .npy array ({e})"),
        })?;
    Ok(header.shape)
}

/// Reads a 1D float64 `.npy` (a line): finite values, at least 2 points.
pub fn read_npy_1d(path: &Path) -> Result<Array1<f64>> {
    let array = read_npy(path)?;
    let shape = array.shape().to_vec();
    let array = array
        .into_dimensionality::<Ix1>()
        .map_err(|_| wrong_shape(path, "1D (n,)", &shape))?;
    if array.len() < 2 {
        return Err(wrong_shape(path, "1D array of at least 2 points", &shape));
    }
    Ok(array)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::array;

    #[test]
    fn round_trip_and_refuse_overwrite() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.npy");
        let a = array![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
        write_npy_2d(&path, false, &a).unwrap();
        assert_eq!(read_npy_2d(&path).unwrap(), a);
        let err = write_npy_2d(&path, false, &(a.clone() * 2.0)).unwrap_err();
        assert!(matches!(err, Error::OutputExists(_)));
        assert_eq!(
            read_npy_2d(&path).unwrap(),
            a,
            "refused write kept the file"
        );
        write_npy_2d(&path, true, &(a.clone() * 2.0)).unwrap();
        assert_eq!(read_npy_2d(&path).unwrap(), a * 2.0);
        // No temporary file is left behind.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn nan_and_wrong_shape_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("nan.npy");
        write_npy_2d(&path, false, &array![[1.0, f64::NAN], [0.0, 0.0]]).unwrap();
        let err = read_npy_2d(&path).unwrap_err();
        assert!(matches!(err, Error::NonFinite { index: 1, .. }), "{err}");
        let line = dir.path().join("line.npy");
        write_npy_1d(&line, false, &array![1.0, 2.0, 3.0]).unwrap();
        assert!(read_npy_2d(&line).unwrap_err().to_string().contains("2D"));
        assert!(read_npy_1d(&line).is_ok());
    }

    #[test]
    fn float32_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f32.npy");
        let a = array![[1.0f32, 2.0], [3.0, 4.0]];
        a.write_npy(File::create(&path).unwrap()).unwrap();
        let err = read_npy_2d(&path).unwrap_err().to_string();
        assert!(err.contains("float64"), "{err}");
    }

    #[test]
    fn npy_shape_reads_the_header_only() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.npy");
        write_npy_2d(&path, false, &Array2::zeros((3, 5))).unwrap();
        assert_eq!(npy_shape(&path).unwrap(), [3, 5]);
        // A header promising far more data than the file holds: the shape is still read.
        let mut bytes = std::fs::read(&path).unwrap();
        let at = bytes.windows(6).position(|w| w == b"(3, 5)").unwrap();
        bytes[at + 1] = b'9';
        bytes.truncate(bytes.len() - 15 * 8);
        std::fs::write(&path, &bytes).unwrap();
        assert_eq!(npy_shape(&path).unwrap(), [9, 5]);
        assert!(read_npy_2d(&path).is_err());
        std::fs::write(&path, b"not npy").unwrap();
        assert!(matches!(npy_shape(&path), Err(Error::BadArrayFile { .. })));
    }

    #[test]
    fn an_uncommitted_batch_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let nested = dir.path().join("a").join("b");
        let mut batch = OutputBatch::new(false);
        batch.create_dir_all(&nested).unwrap();
        batch.write_bytes(&nested.join("x.csv"), b"x").unwrap();
        batch
            .write_npy_2d(&dir.path().join("y.npy"), Array2::zeros((2, 2)).view())
            .unwrap();
        assert!(batch.write_bytes(&nested.join("x.csv"), b"again").is_err());
        drop(batch);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn a_committed_batch_writes_everything() {
        let dir = tempfile::tempdir().unwrap();
        let kept = dir.path().join("kept.csv");
        std::fs::write(&kept, "old").unwrap();
        let mut batch = OutputBatch::new(false);
        assert!(matches!(
            batch.write_bytes(&kept, b"new"),
            Err(Error::OutputExists(_))
        ));
        let fields = dir.path().join("fields");
        batch.create_dir_all(&fields).unwrap();
        let a = array![[1.0, 2.0], [3.0, 4.0]];
        batch.write_npy_2d(&fields.join("p.npy"), a.view()).unwrap();
        batch
            .write_bytes(&dir.path().join("t.csv"), b"t\n")
            .unwrap();
        assert!(
            !dir.path().join("t.csv").exists(),
            "nothing before the commit"
        );
        batch.commit().unwrap();
        assert_eq!(read_npy_2d(&fields.join("p.npy")).unwrap(), a);
        assert_eq!(std::fs::read(dir.path().join("t.csv")).unwrap(), b"t\n");
        assert_eq!(std::fs::read_to_string(&kept).unwrap(), "old");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
        assert_eq!(std::fs::read_dir(&fields).unwrap().count(), 1);
        // Forced: replaces.
        let mut batch = OutputBatch::new(true);
        batch.write_bytes(&kept, b"new").unwrap();
        batch.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&kept).unwrap(), "new");
    }

    #[test]
    fn failed_write_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.bin");
        let err = atomic_write(&path, false, |_| Err(Error::invalid("x", "boom")));
        assert!(err.is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
