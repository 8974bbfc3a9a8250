//! Files: NumPy `.npy` arrays, JSON sidecars, and atomic writes.
//!
//! Every output goes through [`StagedOutputs`] (or [`atomic_write`], its one-file form): the
//! data is written to a hidden temporary file beside the target and renamed over it only
//! once complete, so an interrupted run never leaves a truncated file. A command with several
//! outputs (an array, its sidecar, an image) stages them all and renames them together only
//! after every one was written, so a failure part-way leaves none of them. Outputs are
//! checked before any work starts: each one's folder must exist, none may be a folder,
//! none may be named twice, and none may already exist unless `force` is set.
//! A program that exits on a signal (and so runs no destructor) can learn of every
//! temporary file and folder of an unfinished output through an [`OutputWatcher`] it
//! installs ([`watch_outputs`]) and remove them before it exits; the library keeps no list
//! of its own.
//! Inputs are validated on reading: `.npy` files are read by the bounded parser of
//! [`crate::npy`] (regular files only, any real dtype converted to float64 losslessly, C or
//! Fortran order), must have the expected number of dimensions, and contain finite values
//! only.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use ndarray::{Array1, Array2, ArrayBase, ArrayD, Data, Ix1, Ix2};
use ndarray_npy::WriteNpyExt;
use serde::Serialize;

use crate::{ensure_finite, Error, Result};

/// FNV-1a, 64 bits (Fowler–Noll–Vo: offset basis `0xcbf29ce484222325`, prime
/// `0x100000001b3`): a checksum that detects accidental changes (edits, truncation,
/// corruption), not forgery.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |hash, &b| {
        (hash ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Fails with [`Error::OutputExists`] when `path` exists and `force` is false.
///
/// Call it for every output *before* starting work, so that a refusal loses nothing.
pub fn ensure_new_output(path: &Path, force: bool) -> Result<()> {
    if !force && path.exists() {
        return Err(Error::OutputExists(path.to_path_buf()));
    }
    Ok(())
}

/// Told of the temporary files and folders of unfinished outputs, so that a front end that
/// exits on a signal (without running destructors) can remove them first: installed once
/// per process with [`watch_outputs`]. Every path reported by
/// [`unfinished`](OutputWatcher::unfinished) is later reported by
/// [`finished`](OutputWatcher::finished) (renamed into place, or removed) unless the
/// process ends first.
pub trait OutputWatcher: Send + Sync {
    /// `path`, a temporary file or a folder made for outputs, now exists for an output that
    /// is not committed yet.
    fn unfinished(&self, path: &Path);
    /// `path` no longer needs removing: renamed into place, removed, or (a folder) kept
    /// because its outputs were committed.
    fn finished(&self, path: &Path);
    /// Runs `renames`, the renames of one [`StagedOutputs::commit`]. A watcher that removes
    /// unfinished outputs on a signal runs them under the same lock as that removal, so a
    /// commit is never cut in half; the default just runs them. `renames` calls neither of
    /// the other two methods (they may take the same lock).
    fn commit(&self, renames: &mut dyn FnMut()) {
        renames();
    }
}

static WATCHER: OnceLock<&'static dyn OutputWatcher> = OnceLock::new();

/// Installs the process's [`OutputWatcher`]; outputs staged before are not reported. Fails
/// (giving the watcher back) when one is installed already.
pub fn watch_outputs(
    watcher: &'static dyn OutputWatcher,
) -> std::result::Result<(), &'static dyn OutputWatcher> {
    WATCHER.set(watcher)
}

fn unfinished(path: &Path) {
    if let Some(w) = WATCHER.get() {
        w.unfinished(path);
    }
}

fn finished(path: &Path) {
    if let Some(w) = WATCHER.get() {
        w.finished(path);
    }
}

/// Refuses `path` when it is a symbolic link: the lock, checkpoints and temporary files
/// are never written through a link (one planted in an output folder would redirect the
/// write to the file it names). A missing path is fine.
pub fn refuse_link(path: &Path) -> Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => Err(bad_output(
            path,
            "is a symbolic link; asperity does not write through links here: remove it",
        )),
        _ => Ok(()),
    }
}

/// Refuses `dir` as a folder to write in where it, or a folder above it, exists and is not
/// a folder: `FILE/x: cannot be a folder: FILE is a file, not a folder` (the system would
/// say "Not a directory" of a path below it). A missing path is fine (it is made later).
pub fn check_folder(dir: &Path) -> Result<()> {
    for above in dir.ancestors().take_while(|a| !a.as_os_str().is_empty()) {
        match std::fs::metadata(above) {
            Ok(meta) if meta.is_dir() => return Ok(()),
            Ok(_) if above == dir => {
                return Err(bad_output(dir, "exists and is not a folder"));
            }
            Ok(_) => {
                let reason = format!(
                    "cannot be a folder: {} is a file, not a folder",
                    above.display()
                );
                return Err(bad_output(dir, reason));
            }
            // Missing (or not readable: said by whatever reads it next).
            Err(_) => continue,
        }
    }
    Ok(())
}

/// Adds `O_NOFOLLOW` (where it exists) to `options`: opening a symbolic link then fails
/// (`ELOOP`) instead of opening the file it names.
pub fn no_follow(options: &mut std::fs::OpenOptions) {
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NOFOLLOW);
    }
    #[cfg(not(unix))]
    let _ = options;
}

/// Creates the temporary file `tmp` for writing: a new file (`O_EXCL`), never through a
/// link (`O_EXCL` does not follow one; `O_NOFOLLOW` as well). A file or link already
/// there is an error, not overwritten.
/// Whatever is already at `tmp` carries this process's PID in its name, so it is a
/// leftover of a dead process that had the same PID (or a planted link): it is removed
/// (a link itself, never the file it names) and the creation is tried once more.
fn create_temp(tmp: &Path) -> Result<File> {
    let mut options = std::fs::OpenOptions::new();
    options.write(true).create_new(true);
    no_follow(&mut options);
    match options.open(tmp) {
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
            let _ = std::fs::remove_file(tmp);
            options.open(tmp).map_err(|e| Error::io(tmp, e))
        }
        other => other.map_err(|e| Error::io(tmp, e)),
    }
}

/// Removes the temporary files that writes of `target` killed before they finished (by
/// `SIGKILL`, which runs no clean-up) left beside it: `.NAME.PID.K.tmp[.EXT]` whose PID is
/// no live process. Best effort; called after a successful commit.
fn remove_stale_temps(target: &Path) {
    let (Some(name), Some(folder)) = (target.file_name(), target.parent()) else {
        return;
    };
    let folder = if folder.as_os_str().is_empty() {
        Path::new(".")
    } else {
        folder
    };
    let prefix = format!(".{}.", name.to_string_lossy());
    let Ok(entries) = std::fs::read_dir(folder) else {
        return;
    };
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(rest) = file_name.to_str().and_then(|n| n.strip_prefix(&prefix)) else {
            continue;
        };
        if stale_temp_pid(rest).is_some_and(|pid| !process_alive(pid)) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// The PID of a temporary name's tail `PID.K.tmp[.EXT]`, if it is one.
fn stale_temp_pid(rest: &str) -> Option<u32> {
    let mut parts = rest.splitn(4, '.');
    let pid = parts.next()?.parse::<u32>().ok()?;
    parts.next()?.parse::<usize>().ok()?;
    (parts.next()? == "tmp").then_some(pid)
}

/// Whether process `pid` exists (Unix; elsewhere every process counts as alive, so
/// nothing is removed). This process counts as alive.
fn process_alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        if pid == std::process::id() {
            return true;
        }
        let Ok(pid) = libc::pid_t::try_from(pid) else {
            return true;
        };
        // SAFETY: signal 0 only checks that the process exists; nothing is sent.
        let rc = unsafe { libc::kill(pid, 0) };
        rc == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// The sidecar path of an array file (defined with the sidecar reader,
/// [`crate::input::sidecar_path`]: `input` sits below `io` and `npy`, which both read
/// through it, and imports neither).
pub use crate::input::sidecar_path;

/// The side length `spec.size` recorded in the JSON sidecar of `path`, if it has a
/// sidecar that records one; a sidecar that is corrupt, not a regular file, too large, or
/// gives a size that is not a positive finite number is an error (see
/// [`crate::input::read_sidecar`], the one set of rules for every command).
pub fn sidecar_size(path: &Path) -> Result<Option<f64>> {
    crate::input::sidecar_size(path)
}

fn bad_output(path: &Path, reason: impl Into<String>) -> Error {
    Error::BadOutput {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// Checks one output path before any work (see [`StagedOutputs::new`]) and returns the
/// key that identifies the file it names: the canonical folder joined with the file name,
/// or the canonical path itself where the file exists (so that links are seen through).
fn checked_output_key(path: &Path, force: bool) -> Result<PathBuf> {
    let Some(name) = path.file_name() else {
        return Err(bad_output(path, "is not a file name"));
    };
    if name.len() > 255 {
        return Err(bad_output(
            path,
            format!(
                "its name is {} bytes long; a file name may have at most 255",
                name.len()
            ),
        ));
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    // `exists()` is false for any error: only a folder that is missing is said to be.
    match std::fs::metadata(parent) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(bad_output(
                path,
                format!("folder {} does not exist", parent.display()),
            ));
        }
        #[cfg(unix)]
        Err(e) if e.raw_os_error() == Some(libc::ENOTDIR) => {
            return Err(bad_output(
                path,
                format!(
                    "{} is not a folder (a file stands in its path)",
                    parent.display()
                ),
            ));
        }
        Err(e) => {
            return Err(bad_output(
                path,
                format!("folder {} cannot be accessed ({e})", parent.display()),
            ));
        }
        Ok(_) => {}
    }
    if !parent.is_dir() {
        return Err(bad_output(
            path,
            format!("{} is not a folder", parent.display()),
        ));
    }
    if path.is_dir() {
        return Err(bad_output(path, "is a folder, not a file"));
    }
    ensure_new_output(path, force)?;
    if path.exists() {
        return std::fs::canonicalize(path).map_err(|e| Error::io(path, e));
    }
    let folder = std::fs::canonicalize(parent).map_err(|e| Error::io(parent, e))?;
    Ok(folder.join(name))
}

/// A temporary path beside `path`: `.NAME.PID.K.tmp`, or `.NAME.PID.K.tmp.EXT` where the
/// writer picks the format from the extension (images).
fn temp_path(path: &Path, index: usize, extension: Option<&str>) -> PathBuf {
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let ext = extension.map(|e| format!(".{e}")).unwrap_or_default();
    // A long name is shortened (on a character boundary) so that the temporary name stays
    // within the 255 bytes a file name may have: the output's own name may use them all.
    let suffix = format!(".{}.{index}.tmp{ext}", std::process::id());
    let room = 255usize.saturating_sub(suffix.len() + 1);
    let mut cut = file_name.len().min(room);
    while !file_name.is_char_boundary(cut) {
        cut -= 1;
    }
    let tmp = format!(".{}{suffix}", &file_name[..cut]);
    path.with_file_name(tmp)
}

struct Staged {
    target: PathBuf,
    key: PathBuf,
    tmp: Option<PathBuf>,
}

/// The outputs of one command, written all-or-nothing.
///
/// [`StagedOutputs::new`] checks every output before any work starts; each `write_*`
/// method writes one of them to a synced temporary file beside its target; and
/// [`StagedOutputs::commit`] renames them all into place once every one was written.
/// If anything fails before the commit (or the value is dropped without one), the
/// temporary files are removed and no target is touched.
///
/// ```
/// # let dir = tempfile::tempdir()?;
/// use asperity::io::StagedOutputs;
/// let (a, b) = (dir.path().join("a.txt"), dir.path().join("b.txt"));
/// let mut outputs = StagedOutputs::new([&a, &b], false)?;
/// outputs.write_bytes(&a, b"first")?;
/// outputs.write_bytes(&b, b"second")?;
/// outputs.commit()?;
/// assert_eq!(std::fs::read(&b)?, b"second");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct StagedOutputs {
    force: bool,
    entries: Vec<Staged>,
    /// Folders made by [`StagedOutputs::in_new_folders`], outermost first: removed again
    /// (if still empty) when the outputs are dropped uncommitted.
    created_folders: Vec<PathBuf>,
}

impl StagedOutputs {
    /// Declares the outputs and checks them: each one's folder exists, none is a folder,
    /// no file is named twice (after resolving `.`/`..` and links), and none exists unless
    /// `force` is set.
    pub fn new<P: AsRef<Path>>(paths: impl IntoIterator<Item = P>, force: bool) -> Result<Self> {
        let mut entries: Vec<Staged> = Vec::new();
        for path in paths {
            let path = path.as_ref();
            let key = checked_output_key(path, force)?;
            if let Some(other) = entries.iter().find(|e| e.key == key) {
                let reason = if other.target == path {
                    "is the same file as another output; each output needs its own file".into()
                } else {
                    format!(
                        "is the same file as the output {}; each output needs its own file",
                        other.target.display()
                    )
                };
                return Err(bad_output(path, reason));
            }
            entries.push(Staged {
                target: path.to_path_buf(),
                key,
                tmp: None,
            });
        }
        Ok(StagedOutputs {
            force,
            entries,
            created_folders: Vec::new(),
        })
    }

    /// [`StagedOutputs::new`] for outputs in `folders` that may not exist yet: the missing
    /// folders (and their missing parents) are made first, and removed again if the checks
    /// fail or the outputs are dropped without a commit, so a failed run leaves nothing.
    pub fn in_new_folders<P: AsRef<Path>, Q: AsRef<Path>>(
        folders: impl IntoIterator<Item = Q>,
        paths: impl IntoIterator<Item = P>,
        force: bool,
    ) -> Result<Self> {
        let mut created = CreatedFolders(Vec::new());
        for folder in folders {
            created.create_all(folder.as_ref())?;
        }
        let mut outputs = StagedOutputs::new(paths, force)?;
        outputs.created_folders = std::mem::take(&mut created.0);
        Ok(outputs)
    }

    /// Fails with [`Error::BadOutput`] if an output is the file `input` (which the command
    /// reads) or its JSON sidecar (read for the side length and the generating
    /// parameters): overwriting either would lose what the output was computed from.
    pub fn ensure_not_input(&self, input: &Path) -> Result<()> {
        let sidecar = sidecar_path(input);
        for (file, reason) in [
            (input, format!("is the input file {}", input.display())),
            (
                sidecar.as_path(),
                format!(
                    "is the sidecar {} of the input {} (its size and generating parameters); \
                     choose another output name",
                    sidecar.display(),
                    input.display()
                ),
            ),
        ] {
            let Ok(key) = std::fs::canonicalize(file) else {
                continue; // a missing input is reported by whoever reads it
            };
            if let Some(e) = self.entries.iter().find(|e| e.key == key) {
                return Err(bad_output(&e.target, reason));
            }
        }
        Ok(())
    }

    /// The declared outputs, in order.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.entries.iter().map(|e| e.target.as_path())
    }

    fn index_of(&self, target: &Path) -> Result<usize> {
        self.entries
            .iter()
            .position(|e| e.target == target)
            .ok_or_else(|| bad_output(target, "was not declared as an output"))
    }

    /// Stages `target` by letting `write` create the file at the temporary path it is given
    /// (for writers that open files themselves, e.g. image encoders, which pick the format
    /// from `extension`). On error the temporary file is removed.
    pub fn write_file_with<F, E>(
        &mut self,
        target: &Path,
        extension: Option<&str>,
        write: F,
    ) -> std::result::Result<(), E>
    where
        F: FnOnce(&Path) -> std::result::Result<(), E>,
        E: From<Error>,
    {
        let index = self.index_of(target)?;
        let tmp = temp_path(target, index, extension);
        if let Some(old) = self.entries[index].tmp.take() {
            let _ = std::fs::remove_file(&old);
            finished(&old);
        }
        unfinished(&tmp);
        // Made here, new and not through a link, before the writer opens it by name.
        if let Err(e) = create_temp(&tmp) {
            finished(&tmp);
            return Err(e.into());
        }
        match write(&tmp) {
            Ok(()) => {
                self.entries[index].tmp = Some(tmp);
                Ok(())
            }
            Err(e) => {
                let _ = std::fs::remove_file(&tmp);
                finished(&tmp);
                Err(e)
            }
        }
    }

    /// Stages `target`: `write` fills a buffered temporary file, which is flushed and synced.
    pub fn write_with<F>(&mut self, target: &Path, write: F) -> Result<()>
    where
        F: FnOnce(&mut BufWriter<File>) -> Result<()>,
    {
        self.write_file_with(target, None, |tmp| {
            let mut options = std::fs::OpenOptions::new();
            options.write(true);
            no_follow(&mut options);
            let file = options.open(tmp).map_err(|e| Error::io(tmp, e))?;
            let mut writer = BufWriter::new(file);
            write(&mut writer)?;
            writer.flush().map_err(|e| Error::io(tmp, e))?;
            writer.get_ref().sync_all().map_err(|e| Error::io(tmp, e))
        })
    }

    /// Stages `target` with these bytes.
    pub fn write_bytes(&mut self, target: &Path, bytes: &[u8]) -> Result<()> {
        self.write_with(target, |w| {
            w.write_all(bytes).map_err(|e| Error::io(target, e))
        })
    }

    /// Stages `target` with a value as pretty JSON.
    pub fn write_json<T: Serialize>(&mut self, target: &Path, value: &T) -> Result<()> {
        let text = serde_json::to_string_pretty(value).map_err(|e| Error::Metadata {
            path: target.to_path_buf(),
            reason: e.to_string(),
        })?;
        self.write_bytes(target, format!("{text}\n").as_bytes())
    }

    fn write_npy<A: WriteNpyExt>(&mut self, target: &Path, array: &A) -> Result<()> {
        self.write_with(target, |w| {
            array.write_npy(w).map_err(|e| Error::BadArrayFile {
                path: target.to_path_buf(),
                reason: e.to_string(),
            })
        })
    }

    /// Stages `target` with a 2D float64 array (owned or a view) as `.npy` (C order).
    pub fn write_npy_2d<S: Data<Elem = f64>>(
        &mut self,
        target: &Path,
        array: &ArrayBase<S, Ix2>,
    ) -> Result<()> {
        self.write_npy(target, array)
    }

    /// Stages `target` with a 1D float64 array as `.npy`.
    pub fn write_npy_1d(&mut self, target: &Path, array: &Array1<f64>) -> Result<()> {
        self.write_npy(target, array)
    }

    /// The FNV-1a-64 hash ([`fnv1a64`]) of every output staged so far, by target, read
    /// back from its temporary file: for a record of what a command wrote, staged last and
    /// committed with the outputs it describes.
    pub fn fingerprints(&self) -> Result<Vec<(PathBuf, u64)>> {
        let mut out = Vec::new();
        for e in &self.entries {
            if let Some(tmp) = &e.tmp {
                let bytes = std::fs::read(tmp).map_err(|err| Error::io(tmp, err))?;
                out.push((e.target.clone(), fnv1a64(&bytes)));
            }
        }
        Ok(out)
    }

    /// Renames every staged file into place. Fails, touching no target, if an output was
    /// not written or (without `force`) appeared meanwhile. Should a rename itself fail,
    /// the outputs already renamed that did not exist before are removed again.
    pub fn commit(mut self) -> Result<()> {
        for e in &self.entries {
            if e.tmp.is_none() {
                return Err(bad_output(&e.target, "was declared but never written"));
            }
            ensure_new_output(&e.target, self.force)?;
        }
        let (mut result, mut renamed) = (Ok(()), Vec::new());
        let mut renames = || result = self.rename_all(&mut renamed);
        match WATCHER.get() {
            Some(w) => w.commit(&mut renames),
            None => renames(),
        }
        // Told after the renames (outside the watcher's lock): a signal in between removes
        // paths that are gone, or folders that are no longer empty, which fails harmlessly.
        for tmp in &renamed {
            finished(tmp);
        }
        result?;
        for folder in self.created_folders.drain(..) {
            finished(&folder);
        }
        for e in &self.entries {
            remove_stale_temps(&e.target);
        }
        Ok(())
    }

    /// The renames of [`StagedOutputs::commit`]: on a failure, the outputs already renamed
    /// that did not exist before are removed again, and the temporary files not yet renamed
    /// stay staged (removed on drop).
    /// `done` receives the temporary files renamed.
    fn rename_all(&mut self, done: &mut Vec<PathBuf>) -> Result<()> {
        let mut renamed: Vec<(PathBuf, bool)> = Vec::new();
        for e in &mut self.entries {
            let existed = e.target.exists();
            let Some(tmp) = e.tmp.take() else { continue };
            if let Err(err) = std::fs::rename(&tmp, &e.target) {
                e.tmp = Some(tmp);
                for (path, existed) in renamed {
                    if !existed {
                        let _ = std::fs::remove_file(path);
                    }
                }
                return Err(Error::io(&e.target, err));
            }
            done.push(tmp);
            renamed.push((e.target.clone(), existed));
        }
        Ok(())
    }
}

impl Drop for StagedOutputs {
    fn drop(&mut self) {
        for e in &mut self.entries {
            if let Some(tmp) = e.tmp.take() {
                let _ = std::fs::remove_file(&tmp);
                finished(&tmp);
            }
        }
        drop(CreatedFolders(std::mem::take(&mut self.created_folders)));
    }
}

/// Folders made for outputs, outermost first; removed (if empty) when dropped.
struct CreatedFolders(Vec<PathBuf>);

impl CreatedFolders {
    /// Makes `dir` and its missing parents, recording each.
    fn create_all(&mut self, dir: &Path) -> Result<()> {
        let mut missing = Vec::new();
        let mut next = Some(dir);
        while let Some(d) = next.filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
            missing.push(d.to_path_buf());
            next = d.parent();
        }
        for d in missing.into_iter().rev() {
            std::fs::create_dir(&d).map_err(|e| Error::io(&d, e))?;
            unfinished(&d);
            self.0.push(d);
        }
        if !dir.is_dir() {
            return Err(bad_output(dir, "exists and is not a folder"));
        }
        Ok(())
    }
}

impl Drop for CreatedFolders {
    fn drop(&mut self) {
        for dir in self.0.iter().rev() {
            let _ = std::fs::remove_dir(dir); // only if empty
            finished(dir);
        }
    }
}

/// Writes `path` atomically: `write` fills a temporary file in the same folder, which is
/// flushed, synced and renamed over `path`. On any error the temporary file is removed and
/// `path` is left as it was. The one-output form of [`StagedOutputs`], with its checks.
pub fn atomic_write<F>(path: &Path, force: bool, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    write_one(path, force, |s| s.write_with(path, write))
}

/// Stages one output with `write` and commits it.
fn write_one<F>(path: &Path, force: bool, write: F) -> Result<()>
where
    F: FnOnce(&mut StagedOutputs) -> Result<()>,
{
    let mut staged = StagedOutputs::new([path], force)?;
    write(&mut staged)?;
    staged.commit()
}

/// Writes bytes atomically (see [`atomic_write`]).
pub fn write_bytes(path: &Path, force: bool, bytes: &[u8]) -> Result<()> {
    write_one(path, force, |s| s.write_bytes(path, bytes))
}

/// Writes a value as pretty JSON, atomically.
pub fn write_json<T: Serialize>(path: &Path, force: bool, value: &T) -> Result<()> {
    write_one(path, force, |s| s.write_json(path, value))
}

/// Writes a 2D float64 array as `.npy` (C order), atomically.
pub fn write_npy_2d(path: &Path, force: bool, array: &Array2<f64>) -> Result<()> {
    write_one(path, force, |s| s.write_npy_2d(path, array))
}

/// Writes a 1D float64 array as `.npy`, atomically.
pub fn write_npy_1d(path: &Path, force: bool, array: &Array1<f64>) -> Result<()> {
    write_one(path, force, |s| s.write_npy_1d(path, array))
}

/// The shape recorded in the header of a `.npy` file, read without loading the data (to
/// size the work before reading a large file). Only the header is checked here (by the
/// bounded parser of [`crate::npy`]); the data are validated by [`read_npy`].
pub fn read_npy_shape(path: &Path) -> Result<Vec<usize>> {
    Ok(crate::npy::read_header(path)?.0.shape)
}

/// Reads a `.npy` of any real dtype and dimension as float64 (losslessly, see
/// [`crate::npy`]) and checks that it is not empty and all values are finite.
pub fn read_npy(path: &Path) -> Result<ArrayD<f64>> {
    let array = crate::npy::read(path)?;
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
    fn float32_is_read_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f32.npy");
        let a = array![[1.0f32, 0.1], [3.0, 4.0]];
        a.write_npy(File::create(&path).unwrap()).unwrap();
        assert_eq!(read_npy_2d(&path).unwrap(), a.mapv(f64::from));
    }

    #[test]
    fn failed_write_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.bin");
        let err = atomic_write(&path, false, |_| Err(Error::invalid("x", "boom")));
        assert!(err.is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn staged_outputs_are_checked_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let a = d.join("a.npy");
        let missing = d.join("nowhere").join("a.png");
        let err = StagedOutputs::new([&a, &missing], false).err().unwrap();
        assert!(matches!(err, Error::BadOutput { .. }), "{err}");
        assert!(err.to_string().contains("does not exist"), "{err}");
        // The same file named twice, also through `.`/`..`.
        let same = d.join("sub").join("..").join("a.npy");
        std::fs::create_dir(d.join("sub")).unwrap();
        for twin in [a.clone(), d.join(".").join("a.npy"), same] {
            let err = StagedOutputs::new([&a, &twin], true).err().unwrap();
            assert!(err.to_string().contains("same file"), "{err}");
        }
        // A folder is refused even with force; an existing file only without it.
        let err = StagedOutputs::new([d.join("sub")], true).err().unwrap();
        assert!(err.to_string().contains("is a folder"), "{err}");
        std::fs::write(&a, b"old").unwrap();
        let err = StagedOutputs::new([&a], false).err().unwrap();
        assert!(matches!(err, Error::OutputExists(_)), "{err}");
        let staged = StagedOutputs::new([&a], true).unwrap();
        let err = staged.ensure_not_input(&a).unwrap_err();
        assert!(err.to_string().contains("input"), "{err}");
        staged.ensure_not_input(&d.join("other.npy")).unwrap();
        assert_eq!(entries(d), ["a.npy", "sub"]);
    }

    #[test]
    fn staged_outputs_are_all_or_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let (a, b, c) = (d.join("a.npy"), d.join("a.npy.json"), d.join("a.png"));
        // A failure part-way leaves nothing, not even the outputs already staged.
        {
            let mut staged = StagedOutputs::new([&a, &b, &c], false).unwrap();
            staged.write_npy_1d(&a, &array![1.0, 2.0]).unwrap();
            staged.write_json(&b, &serde_json::json!({"x": 1})).unwrap();
            let err = staged
                .write_with(&c, |_| Err(Error::invalid("png", "boom")))
                .unwrap_err();
            assert!(err.to_string().contains("boom"));
        }
        assert!(entries(d).is_empty(), "{:?}", entries(d));
        // Committing with an output never written fails and touches nothing.
        let mut staged = StagedOutputs::new([&a, &b], false).unwrap();
        staged.write_bytes(&a, b"x").unwrap();
        let err = staged.commit().unwrap_err();
        assert!(err.to_string().contains("never written"), "{err}");
        assert!(entries(d).is_empty(), "{:?}", entries(d));
        // An output that appeared meanwhile is not overwritten without force.
        let mut staged = StagedOutputs::new([&a, &b], false).unwrap();
        staged.write_bytes(&a, b"new a").unwrap();
        staged.write_bytes(&b, b"new b").unwrap();
        std::fs::write(&b, b"someone else's").unwrap();
        assert!(matches!(staged.commit(), Err(Error::OutputExists(_))));
        assert_eq!(entries(d), ["a.npy.json"]);
        assert_eq!(std::fs::read(&b).unwrap(), b"someone else's");
        // Writing an undeclared output is an error; a complete set is renamed into place.
        let mut staged = StagedOutputs::new([&a, &b], true).unwrap();
        assert!(staged.write_bytes(&c, b"?").is_err());
        staged.write_bytes(&a, b"A").unwrap();
        staged
            .write_file_with(&b, Some("json"), |tmp| {
                assert!(tmp.to_string_lossy().ends_with(".json"));
                std::fs::write(tmp, b"B").map_err(|e| Error::io(tmp, e))
            })
            .unwrap();
        staged.commit().unwrap();
        assert_eq!(entries(d), ["a.npy", "a.npy.json"]);
        assert_eq!(std::fs::read(&a).unwrap(), b"A");
        assert_eq!(std::fs::read(&b).unwrap(), b"B");
    }

    #[cfg(unix)]
    #[test]
    fn a_link_planted_at_the_temporary_name_is_never_written_through() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim.txt");
        std::fs::write(&victim, "precious").unwrap();
        let out = dir.path().join("out.json");
        // The temporary names are predictable (PID and index): plant a link at each.
        for (i, ext) in [(0, None), (0, Some("png"))] {
            std::os::unix::fs::symlink(&victim, temp_path(&out, i, ext)).unwrap();
        }
        write_bytes(&out, false, b"result").unwrap();
        let mut staged = StagedOutputs::new([dir.path().join("out.png")], false).unwrap();
        let png = dir.path().join("out.png");
        staged
            .write_file_with(&png, Some("png"), |tmp| {
                std::fs::write(tmp, b"image").map_err(|e| Error::io(tmp, e))
            })
            .unwrap();
        staged.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
        assert_eq!(std::fs::read(&out).unwrap(), b"result");
        assert_eq!(std::fs::read(&png).unwrap(), b"image");
    }

    #[cfg(unix)]
    #[test]
    fn temporary_files_of_killed_writes_are_removed_by_the_next_commit() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("surface.npy");
        // A process that no longer exists: a child that has exited and been reaped.
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let stale = dir.path().join(format!(".surface.npy.{dead}.0.tmp"));
        let stale_png = dir.path().join(format!(".surface.npy.{dead}.1.tmp.png"));
        let live = dir
            .path()
            .join(format!(".surface.npy.{}.7.tmp", std::process::id()));
        let other = dir.path().join(format!(".other.npy.{dead}.0.tmp"));
        for p in [&stale, &stale_png, &live, &other] {
            std::fs::write(p, b"partial").unwrap();
        }
        write_bytes(&out, false, b"done").unwrap();
        assert!(!stale.exists() && !stale_png.exists());
        assert!(live.exists(), "a live process's temporary file is kept");
        assert!(
            other.exists(),
            "another output's temporary file is not touched"
        );
    }

    /// Issue 33 item 15: an output under a file (a path through a file, not a folder)
    /// said "does not exist" of a path that exists.
    #[test]
    fn an_output_under_a_file_is_not_said_to_be_in_a_missing_folder() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("plain.txt");
        std::fs::write(&file, "x").unwrap();
        let err = write_bytes(&file.join("sub").join("out.csv"), false, b"x")
            .unwrap_err()
            .to_string();
        assert!(!err.contains("does not exist"), "{err}");
        assert!(err.contains("is not a folder"), "{err}");
    }

    #[test]
    fn atomic_write_into_a_missing_folder_is_a_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no").join("x.csv");
        let err = write_bytes(&path, false, b"q,psd\n")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("does not exist") && err.contains("x.csv"),
            "{err}"
        );
    }

    #[test]
    fn new_folders_are_removed_unless_committed() {
        let dir = tempfile::tempdir().unwrap();
        let fields = dir.path().join("a/b");
        let out = fields.join("p.npy");
        // Dropped uncommitted (an error on the way): the folders made for it go too.
        let mut staged = StagedOutputs::in_new_folders([&fields], [&out], false).unwrap();
        assert!(fields.is_dir());
        staged.write_bytes(&out, b"x").unwrap();
        drop(staged);
        assert!(!dir.path().join("a").exists());
        // Refused outputs (named twice) leave no folder behind either.
        assert!(StagedOutputs::in_new_folders([&fields], [&out, &out], false).is_err());
        assert!(!dir.path().join("a").exists());
        // Committed: folders and file stay.
        let mut staged = StagedOutputs::in_new_folders([&fields], [&out], false).unwrap();
        staged.write_bytes(&out, b"x").unwrap();
        staged.commit().unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), b"x");
    }

    #[test]
    fn npy_shape_is_read_from_the_header() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.npy");
        write_npy_2d(&path, false, &Array2::zeros((3, 5))).unwrap();
        assert_eq!(read_npy_shape(&path).unwrap(), [3, 5]);
        let line = dir.path().join("l.npy");
        write_npy_1d(&line, false, &Array1::zeros(7)).unwrap();
        assert_eq!(read_npy_shape(&line).unwrap(), [7]);
        let junk = dir.path().join("junk.npy");
        std::fs::write(&junk, b"hello world, not an array").unwrap();
        let err = read_npy_shape(&junk).unwrap_err().to_string();
        assert!(err.contains("not a .npy array"), "{err}");
    }
}
