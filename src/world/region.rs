//! Minecraft Anvil region files (`r.X.Z.mca`): 32×32 chunks of compressed NBT per file.
//!
//! Layout: a 4096-byte table of 1024 big-endian locations (`sector offset << 8 | sector count`),
//! a 4096-byte table of 1024 big-endian timestamps, then 4096-byte sectors. A stored chunk is a
//! big-endian length `L` (bytes that follow, compression byte included), one compression byte
//! and `L - 1` bytes of data, padded to whole sectors.
//!
//! The file is untrusted input: a damaged header or chunk makes that chunk read as
//! [`ChunkError::Corrupt`], never a panic or a huge allocation, and writes are ordered so that a
//! process killed at any point leaves every chunk readable in its old or its new version.

use std::fs::{File, OpenOptions};
use std::io::{self, Read, Write};
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};

use flate2::read::{GzDecoder, ZlibDecoder};
use flate2::write::ZlibEncoder;
use flate2::Compression;

/// Bytes in a sector, the unit of allocation in the file.
const SECTOR: u64 = 4096;
/// The two header tables (locations, timestamps) fill the first two sectors.
const HEADER_SECTORS: usize = 2;
/// Chunks in one region (32 × 32).
const CHUNKS: usize = 1024;
/// The sector count is one byte in the location entry; bigger chunks need `.mcc` files, which
/// we never write.
const MAX_SECTORS: usize = 255;
/// Sectors a location entry can address (its offset has 24 bits).
const MAX_OFFSET: usize = 1 << 24;
/// Bytes before the data of a stored chunk: the length and the compression byte.
const CHUNK_HEADER: usize = 5;
/// Largest decompressed chunk accepted. Real chunks are at most a few MB of NBT; without a cap a
/// 1 MB zlib "bomb" could inflate to about a gigabyte.
const MAX_DECOMPRESSED: u64 = 64 << 20;

/// Region coordinates (one file holds 32×32 chunks).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct RegionPos {
    /// Region x (chunk x divided by 32, rounded down).
    pub x: i32,
    /// Region z (chunk z divided by 32, rounded down).
    pub z: i32,
}

impl RegionPos {
    /// The region holding chunk (`chunk_x`, `chunk_z`): floor division by 32, so chunk -1 is in
    /// region -1, not 0.
    pub fn of_chunk(chunk_x: i32, chunk_z: i32) -> RegionPos {
        RegionPos { x: chunk_x.div_euclid(32), z: chunk_z.div_euclid(32) }
    }

    /// The file's name, as Minecraft names it: `r.-1.3.mca`.
    pub fn file_name(&self) -> String {
        format!("r.{}.{}.mca", self.x, self.z)
    }

    /// The region a file name denotes, `None` for anything that is not exactly a name
    /// [`file_name`](Self::file_name) would produce (so `r.+1.2.mca` or `r.01.2.mca` are not
    /// mistaken for region 1, 2 and two names never map to one region).
    pub fn parse_file_name(name: &str) -> Option<RegionPos> {
        let coords = name.strip_prefix("r.")?.strip_suffix(".mca")?;
        let (x, z) = coords.split_once('.')?;
        let pos = RegionPos { x: x.parse().ok()?, z: z.parse().ok()? };
        (pos.file_name() == name).then_some(pos)
    }
}

/// Chunk's index inside its region: (chunk_x.rem_euclid(32), chunk_z.rem_euclid(32)).
pub fn local(chunk_x: i32, chunk_z: i32) -> (usize, usize) {
    (chunk_x.rem_euclid(32) as usize, chunk_z.rem_euclid(32) as usize)
}

/// zlib-compresses chunk NBT for [`RegionFile::write`] (done on worker threads, not under the
/// file lock). The fastest level: chunks are generated faster than a higher level can squeeze
/// them, and the bytes it would save are a few percent of a cheap resource.
pub fn compress(nbt: &[u8]) -> Vec<u8> {
    // Typical NBT compresses 5–10×; reserving a quarter avoids most regrowth without waste.
    let mut encoder = ZlibEncoder::new(Vec::with_capacity(nbt.len() / 4 + 64), Compression::fast());
    // Writing into a Vec cannot fail: the only errors would come from the sink.
    encoder.write_all(nbt).expect("compressing into memory");
    encoder.finish().expect("compressing into memory")
}

/// Why a region file could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum RegionError {
    /// Opening, creating or reading the header failed.
    #[error("region file {}: {source}", path.display())]
    Io {
        /// The file (or, when creating it, its directory).
        path: PathBuf,
        /// The underlying error.
        source: io::Error,
    },
    /// The file is not empty but shorter than the 8192-byte header: not a region file, or one
    /// cut short while being created. Left alone rather than overwritten, since it may be
    /// someone's data.
    #[error("region file {} is {len} bytes, shorter than its 8192-byte header", path.display())]
    TooShort {
        /// The file.
        path: PathBuf,
        /// Its length in bytes.
        len: u64,
    },
}

/// Why a stored chunk could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ChunkError {
    /// The header entry or the stored bytes are damaged or in a form we cannot read.
    #[error("corrupt chunk: {reason}")]
    Corrupt {
        /// What is wrong, for the log.
        reason: String,
    },
    /// Reading the file failed (not a problem with its contents).
    #[error("reading chunk: {0}")]
    Io(#[from] io::Error),
}

fn corrupt(reason: impl Into<String>) -> ChunkError {
    ChunkError::Corrupt { reason: reason.into() }
}

/// One open region file: its header and a map of used sectors are kept in memory so reads need
/// one or two positional reads and writes can find free space without scanning the file.
pub struct RegionFile {
    path: PathBuf,
    file: File,
    /// The location table as on disk (0 = absent).
    locations: Vec<u32>,
    /// Why a present entry cannot be trusted (points into the header, past the end of the file,
    /// or over another entry), decided at open; `None` for good and absent entries.
    bad: Vec<Option<String>>,
    /// One flag per sector of the file: true when the header or a good entry owns it. Sectors of
    /// bad entries are free: nothing valid can be in them.
    used: Vec<bool>,
}

/// Index of a chunk in the header tables.
fn index(lx: usize, lz: usize) -> usize {
    debug_assert!(lx < 32 && lz < 32, "local chunk coordinates out of range: {lx}, {lz}");
    (lx & 31) + (lz & 31) * 32
}

/// A location entry's sector offset and sector count.
fn split(location: u32) -> (usize, usize) {
    ((location >> 8) as usize, (location & 0xff) as usize)
}

impl RegionFile {
    /// Opens (creating if `create` and missing) the file. A file shorter than 8192 bytes that
    /// is empty is initialised; a non-empty file shorter than the header → RegionError naming the path.
    /// Header entries that point into the header, past the end of the file, or overlap another
    /// entry are NOT an open error: those chunks read as ChunkError::Corrupt (and are dropped
    /// from the used-sector map so their space is not trusted). When a later write takes sectors
    /// such an entry claims, the entry is zeroed on disk first, so the new chunk cannot be seen
    /// as overlapping it after a reopen.
    pub fn open(path: &Path, create: bool) -> Result<RegionFile, RegionError> {
        let io_error = |source| RegionError::Io { path: path.to_path_buf(), source };
        let file =
            OpenOptions::new().read(true).write(true).create(create).truncate(false).open(path).map_err(io_error)?;
        let mut len = file.metadata().map_err(io_error)?.len();
        if len == 0 {
            // A new file, or one created but killed before its header was written.
            file.write_all_at(&[0; 2 * SECTOR as usize], 0).map_err(io_error)?;
            len = 2 * SECTOR;
        } else if len < 2 * SECTOR {
            return Err(RegionError::TooShort { path: path.to_path_buf(), len });
        }
        let mut table = [0u8; SECTOR as usize];
        file.read_exact_at(&mut table, 0).map_err(io_error)?;
        let locations: Vec<u32> =
            table.chunks_exact(4).map(|b| u32::from_be_bytes(b.try_into().expect("4 bytes"))).collect();

        // A partly written last sector still counts: a chunk whose bytes fit in it is readable,
        // and one that does not fails its read as truncated.
        let sectors = len.div_ceil(SECTOR) as usize;
        // How many entries claim each sector, to find overlaps without trusting entry order.
        let mut claims = vec![0u8; sectors];
        claims[..HEADER_SECTORS].fill(1);
        let mut bad: Vec<Option<String>> = vec![None; CHUNKS];
        for (i, &location) in locations.iter().enumerate() {
            let (offset, count) = split(location);
            if location == 0 {
                continue;
            } else if count == 0 {
                bad[i] = Some(format!("location entry {location:#x} has no sectors"));
            } else if offset < HEADER_SECTORS {
                bad[i] = Some(format!("location entry points into the header (sector {offset})"));
            } else if offset + count > sectors {
                bad[i] = Some(format!(
                    "sectors {offset}..{} lie past the end of the file ({sectors} sectors)",
                    offset + count
                ));
            } else {
                claims[offset..offset + count].iter_mut().for_each(|c| *c = c.saturating_add(1));
            }
        }
        // Both entries of an overlap are bad: either may be a stale pointer, and serving one
        // chunk's terrain at another's place is worse than regenerating both.
        for (i, &location) in locations.iter().enumerate() {
            let (offset, count) = split(location);
            if location != 0 && bad[i].is_none() && claims[offset..offset + count].iter().any(|&c| c > 1) {
                bad[i] = Some(format!("sectors {offset}..{} overlap another chunk", offset + count));
            }
        }
        let mut used = vec![false; sectors];
        used[..HEADER_SECTORS].fill(true);
        for (i, &location) in locations.iter().enumerate() {
            let (offset, count) = split(location);
            if location != 0 && bad[i].is_none() {
                used[offset..offset + count].fill(true);
            }
        }
        Ok(RegionFile { path: path.to_path_buf(), file, locations, bad, used })
    }

    /// The file's path, for error messages.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Whether the header says chunk (`lx`, `lz`) is present and its entry is not known to be bad
    /// (its data may still turn out corrupt when read).
    pub fn contains(&self, lx: usize, lz: usize) -> bool {
        let i = index(lx, lz);
        self.locations[i] != 0 && self.bad[i].is_none()
    }

    /// Decompressed chunk bytes, Ok(None) when absent, Err(ChunkError) when the stored data
    /// cannot be read: length 0 or beyond its sectors, unknown/unsupported compression,
    /// decompression failure, external .mcc chunk (bit 128 of the compression byte: unsupported).
    pub fn read(&mut self, lx: usize, lz: usize) -> Result<Option<Vec<u8>>, ChunkError> {
        let i = index(lx, lz);
        if let Some(reason) = &self.bad[i] {
            return Err(corrupt(reason.clone()));
        }
        let (offset, count) = split(self.locations[i]);
        if self.locations[i] == 0 {
            return Ok(None);
        }
        let start = offset as u64 * SECTOR;
        let mut head = [0u8; CHUNK_HEADER];
        read_at(&self.file, &mut head, start)?;
        let length = u32::from_be_bytes([head[0], head[1], head[2], head[3]]) as usize;
        let compression = head[4];
        if length == 0 {
            return Err(corrupt("length field is 0"));
        }
        // The cap that keeps a damaged length from allocating more than the chunk's sectors.
        if length + 4 > count * SECTOR as usize {
            return Err(corrupt(format!("length {length} does not fit in its {count} sectors")));
        }
        let mut data = vec![0u8; length - 1];
        read_at(&self.file, &mut data, start + CHUNK_HEADER as u64)?;
        let decoded = match compression {
            1 => inflate(GzDecoder::new(&data[..]), "gzip"),
            2 => inflate(ZlibDecoder::new(&data[..]), "zlib"),
            3 => Ok(data),
            4 => Err(corrupt("LZ4 compression (type 4) is unsupported")),
            c if c & 0x80 != 0 => Err(corrupt(format!("stored in an external .mcc file (type {c}): unsupported"))),
            c => Err(corrupt(format!("unknown compression type {c}"))),
        }?;
        Ok(Some(decoded))
    }

    /// Stores already-compressed (zlib) data with `timestamp` (seconds). CRASH SAFETY: the new data
    /// is written into free sectors (never over the sectors this chunk currently uses, so a kill
    /// mid-write leaves the old version valid), the location entry is updated only after the data
    /// write returned, and the old sectors become free afterwards (in memory). Reuse the first
    /// free run that fits (first-fit), else append at the end. Pad the file to whole sectors.
    /// Chunks > 255 sectors: return an io::Error (InvalidInput) naming the chunk; we never make them.
    ///
    /// Ordering protects against the process dying, not against power loss: the OS may reorder
    /// unsynced writes, which is why callers [`sync`](Self::sync) before recording progress.
    pub fn write(&mut self, lx: usize, lz: usize, zlib: &[u8], timestamp: u32) -> io::Result<()> {
        let i = index(lx, lz);
        let count = (zlib.len() + CHUNK_HEADER).div_ceil(SECTOR as usize);
        if count > MAX_SECTORS {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "chunk {lx}, {lz} of {}: {} compressed bytes need {count} sectors, more than {MAX_SECTORS}",
                    self.path.display(),
                    zlib.len()
                ),
            ));
        }
        let offset = self.find_free(count);
        // The location entry has 24 bits of sector offset: a file past 64 GiB cannot address more.
        if offset + count > MAX_OFFSET {
            return Err(io::Error::other(format!(
                "chunk {lx}, {lz} of {}: the region file is full ({MAX_OFFSET} sectors)",
                self.path.display()
            )));
        }
        self.forget_bad_entries_in(offset, count)?;

        // One write of the whole padded run: the file always ends on a sector boundary.
        let mut buf = Vec::with_capacity(count * SECTOR as usize);
        buf.extend_from_slice(&(zlib.len() as u32 + 1).to_be_bytes());
        buf.push(2);
        buf.extend_from_slice(zlib);
        buf.resize(count * SECTOR as usize, 0);
        self.file.write_all_at(&buf, offset as u64 * SECTOR)?;

        // The timestamp first: it means nothing without the location, which is the commit point.
        self.file.write_all_at(&timestamp.to_be_bytes(), SECTOR + 4 * i as u64)?;
        let location = ((offset as u32) << 8) | count as u32;
        self.set_location(i, location)?;
        self.mark(offset, count, true);
        Ok(())
    }

    /// Removes the chunk (location entry zeroed first, then sectors freed).
    pub fn delete(&mut self, lx: usize, lz: usize) -> io::Result<()> {
        let i = index(lx, lz);
        if self.locations[i] == 0 {
            return Ok(());
        }
        self.set_location(i, 0)?;
        self.file.write_all_at(&[0; 4], SECTOR + 4 * i as u64)
    }

    /// fsync (data + header) — called before progress that claims these chunks is saved.
    pub fn sync(&self) -> io::Result<()> {
        self.file.sync_all()
    }

    /// Every present chunk's local coordinates: the chunks for which [`contains`](Self::contains)
    /// is true, so entries known to be bad are left out (they are to be regenerated).
    pub fn chunks(&self) -> Vec<(usize, usize)> {
        (0..CHUNKS).filter(|&i| self.locations[i] != 0 && self.bad[i].is_none()).map(|i| (i % 32, i / 32)).collect()
    }

    /// The first run of `count` free sectors (sectors past the end of the file are free, so a
    /// free tail is extended rather than skipped).
    fn find_free(&self, count: usize) -> usize {
        let mut run = 0;
        for (sector, &used) in self.used.iter().enumerate().skip(HEADER_SECTORS) {
            if used {
                run = 0;
            } else {
                run += 1;
                if run == count {
                    return sector + 1 - count;
                }
            }
        }
        self.used.len() - run
    }

    /// Zeroes on disk (and forgets) every bad entry claiming a sector of `offset..offset+count`,
    /// before new data goes there: such an entry left in the header would make the new chunk look
    /// like an overlap (and so corrupt) at the next open. Those entries were unreadable anyway.
    fn forget_bad_entries_in(&mut self, offset: usize, count: usize) -> io::Result<()> {
        for i in 0..CHUNKS {
            let (bad_offset, bad_count) = split(self.locations[i]);
            if self.bad[i].is_some() && bad_offset < offset + count && offset < bad_offset + bad_count {
                self.set_location(i, 0)?;
            }
        }
        Ok(())
    }

    /// Writes location entry `i` to disk, then updates memory; the sectors the entry held
    /// become free (in memory only, so they are not reused before the new entry is on disk).
    fn set_location(&mut self, i: usize, location: u32) -> io::Result<()> {
        self.file.write_all_at(&location.to_be_bytes(), 4 * i as u64)?;
        let (old_offset, old_count) = split(self.locations[i]);
        if self.locations[i] != 0 && self.bad[i].is_none() {
            self.mark(old_offset, old_count, false);
        }
        self.locations[i] = location;
        self.bad[i] = None;
        Ok(())
    }

    /// Marks sectors `offset..offset+count` used or free, growing the map for appended sectors.
    fn mark(&mut self, offset: usize, count: usize, used: bool) {
        if self.used.len() < offset + count {
            self.used.resize(offset + count, false);
        }
        self.used[offset..offset + count].fill(used);
    }
}

/// A positional read where the file ending early means the chunk is truncated (corrupt), not
/// that the disk failed.
fn read_at(file: &File, buf: &mut [u8], at: u64) -> Result<(), ChunkError> {
    file.read_exact_at(buf, at).map_err(|e| match e.kind() {
        io::ErrorKind::UnexpectedEof => corrupt("the file ends inside the chunk (truncated)"),
        _ => ChunkError::Io(e),
    })
}

/// Decompresses all of `decoder`, refusing output beyond [`MAX_DECOMPRESSED`].
fn inflate(decoder: impl Read, kind: &str) -> Result<Vec<u8>, ChunkError> {
    let mut out = Vec::new();
    decoder
        .take(MAX_DECOMPRESSED + 1)
        .read_to_end(&mut out)
        .map_err(|e| corrupt(format!("{kind} decompression failed: {e}")))?;
    if out.len() as u64 > MAX_DECOMPRESSED {
        return Err(corrupt(format!("decompresses to more than {MAX_DECOMPRESSED} bytes")));
    }
    Ok(out)
}

#[cfg(test)]
#[path = "region_tests.rs"]
mod tests;
