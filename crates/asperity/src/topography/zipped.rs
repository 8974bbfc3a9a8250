//! Members of the zip archives inside measured-topography files (Keyence VK6/VK7 and ZON,
//! Mitutoyo `.xlsx`), read so that a zip bomb costs neither memory nor time, and the
//! Zstandard layer of Keyence `KPK1` members.
//!
//! A member is read only where its declared (uncompressed) size is within the caller's cap
//! and within what its compressed bytes can inflate to: deflate's largest ratio is about
//! 1032 (a 258-byte match costs at least two bits), so a stored or deflated member
//! declaring more than [`MAX_RATIO`] times its compressed size is refused before anything
//! is allocated. At most one byte past the declared size is inflated, a member that
//! inflates to more or fewer bytes than it declares is refused, and zip checks its CRC-32.
//!
//! Zstandard's ratio has no such bound (one block can repeat a byte 128 Ki times), so a
//! Zstandard stream is read through [`zstd`], a reader that the caller bounds by what the
//! data say they hold (e.g. a grid's header), never by the stream's own claims.

use std::io::{Read, Seek};

use zip::ZipArchive;

use super::bytes::bad;
use crate::Result;

/// The largest ratio of inflated to compressed size accepted for a deflated member.
pub(crate) const MAX_RATIO: u64 = 1100;
/// The largest Zstandard window accepted (the decoder allocates it as the data arrive).
const MAX_WINDOW: u64 = 64 << 20;

/// Reads the member `name` of at most `cap` bytes (see the module docs).
pub(crate) fn member<R: Read + Seek>(
    archive: &mut ZipArchive<R>,
    format: &'static str,
    name: &str,
    cap: u64,
) -> Result<Vec<u8>> {
    let file = archive
        .by_name(name)
        .map_err(|e| bad(format, format!("{name}: {e}")))?;
    let declared = declared_size(&file, format, name, cap)?;
    crate::memory::ensure_fits(
        &format!("reading {name} of a {format} file"),
        Some(declared),
    )?;
    let mut data = Vec::with_capacity(declared as usize);
    file.take(declared + 1)
        .read_to_end(&mut data)
        .map_err(|e| bad(format, format!("{name}: {e}")))?;
    if data.len() as u64 != declared {
        return Err(bad(
            format,
            format!("{name} inflates to more or fewer than its {declared} bytes"),
        ));
    }
    Ok(data)
}

/// The size `file` (the member `name`) declares, refused unless within `cap` and within
/// what its compressed bytes can inflate to ([`MAX_RATIO`]); nothing is allocated.
pub(crate) fn declared_size<R: Read>(
    file: &zip::read::ZipFile<'_, R>,
    format: &'static str,
    name: &str,
    cap: u64,
) -> Result<u64> {
    let (declared, packed) = (file.size(), file.compressed_size());
    if declared > cap || declared > packed.saturating_mul(MAX_RATIO).max(1 << 16) {
        return Err(bad(
            format,
            format!("{name} declares {declared} bytes from {packed} compressed: refused"),
        ));
    }
    Ok(declared)
}

/// Whether the archive has a member `name`.
pub(crate) fn has<R: Read + Seek>(archive: &ZipArchive<R>, name: &str) -> bool {
    archive.index_for_name(name).is_some()
}

/// A reader of the Zstandard frame `frame` (one frame, as `zstd` and Keyence write
/// them), its window held to [`MAX_WINDOW`]; its errors are worded as `name`'s.
pub(crate) fn zstd<'a>(
    format: &'static str,
    name: &str,
    frame: &'a [u8],
) -> Result<impl Read + 'a> {
    ruzstd::decoding::StreamingDecoder::new_with_max_window_size(frame, MAX_WINDOW).map_err(|e| {
        bad(
            format,
            format!("{name}: not a readable Zstandard stream ({e})"),
        )
    })
}
