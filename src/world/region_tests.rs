use std::fs::OpenOptions;
use std::io::{Read, Write};
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};
use std::time::Instant;

use flate2::read::ZlibDecoder;
use flate2::write::GzEncoder;

use super::*;

/// Deterministic bytes that zlib cannot shrink, so a chunk's sector count is predictable.
fn noise(seed: u64, len: usize) -> Vec<u8> {
    let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    (0..len)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state as u8
        })
        .collect()
}

/// NBT-like content: mostly repeated longs (block-state palettes, heightmaps) with some variation.
fn nbt_like(len: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(len);
    let mut i = 0u64;
    while out.len() < len {
        let value: u64 = if i % 64 < 48 { 0x0011_2233_0011_2233 } else { i.wrapping_mul(0x9e37_79b9) >> 5 };
        out.extend_from_slice(&value.to_be_bytes());
        if i % 512 == 0 {
            out.extend_from_slice(b"\x0a\x00\x0cblock_states\x09\x00\x07palette");
        }
        i += 1;
    }
    out.truncate(len);
    out
}

/// Stored "zlib" bytes of incompressible noise that fill `sectors` sectors once framed (the
/// compressor's fast level may enlarge noise by a few per cent: the noise is shortened until
/// it fits).
fn payload(seed: u64, sectors: usize) -> Vec<u8> {
    let mut len = sectors * 4096 - 64;
    loop {
        let bytes = compress(&noise(seed, len));
        if bytes.len() + 5 <= sectors * 4096 {
            assert!(bytes.len() + 5 > (sectors - 1) * 4096, "{sectors} sectors");
            return bytes;
        }
        len -= 64;
    }
}

fn new_region(dir: &Path) -> (PathBuf, RegionFile) {
    let path = dir.join(RegionPos { x: 0, z: 0 }.file_name());
    let region = RegionFile::open(&path, true).expect("create");
    (path, region)
}

fn location(path: &Path, lx: usize, lz: usize) -> (u64, u64) {
    let mut raw = [0u8; 4];
    std::fs::File::open(path).unwrap().read_exact_at(&mut raw, 4 * (lx + lz * 32) as u64).unwrap();
    let value = u32::from_be_bytes(raw);
    ((value >> 8) as u64, (value & 0xff) as u64)
}

fn set_location(path: &Path, lx: usize, lz: usize, value: u32) {
    patch(path, 4 * (lx + lz * 32) as u64, &value.to_be_bytes());
}

fn patch(path: &Path, at: u64, bytes: &[u8]) {
    OpenOptions::new().write(true).open(path).unwrap().write_all_at(bytes, at).unwrap();
}

/// Byte offset of a chunk's stored length field.
fn chunk_start(path: &Path, lx: usize, lz: usize) -> u64 {
    location(path, lx, lz).0 * 4096
}

fn assert_corrupt(result: Result<Option<Vec<u8>>, ChunkError>, what: &str) -> String {
    match result {
        Err(ChunkError::Corrupt { reason }) => reason,
        other => panic!("{what}: expected ChunkError::Corrupt, got {other:?}"),
    }
}

/// A region with three small good chunks at (0,0), (1,0), (2,0), for the corruption tests.
fn three_chunks(dir: &Path) -> PathBuf {
    let (path, mut region) = new_region(dir);
    for lx in 0..3 {
        region.write(lx, 0, &compress(&nbt_like(2000 + lx)), 7).unwrap();
    }
    path
}

fn assert_others_fine(path: &Path, skip: &[usize]) {
    let mut region = RegionFile::open(path, false).expect("a damaged chunk must not fail the open");
    for lx in (0..3).filter(|lx| !skip.contains(lx)) {
        assert_eq!(region.read(lx, 0).unwrap().unwrap(), nbt_like(2000 + lx), "chunk {lx}");
    }
}

#[test]
fn region_pos_floor_division_and_file_names() {
    assert_eq!(RegionPos::of_chunk(0, 31), RegionPos { x: 0, z: 0 });
    assert_eq!(RegionPos::of_chunk(32, -1), RegionPos { x: 1, z: -1 });
    assert_eq!(RegionPos::of_chunk(-32, -33), RegionPos { x: -1, z: -2 });
    assert_eq!(RegionPos { x: -1, z: 3 }.file_name(), "r.-1.3.mca");
    for pos in [RegionPos { x: -1, z: 3 }, RegionPos { x: i32::MIN, z: i32::MAX }, RegionPos { x: 0, z: -0 }] {
        assert_eq!(RegionPos::parse_file_name(&pos.file_name()), Some(pos));
    }
    for name in ["r.1.mca", "r.a.2.mca", "r.+1.2.mca", "r.01.2.mca", "r.1.2.mcr", "r.1.2.3.mca", "x.1.2.mca", "r..mca"]
    {
        assert_eq!(RegionPos::parse_file_name(name), None, "{name}");
    }
    assert_eq!(local(-1, -32), (31, 0));
    assert_eq!(local(33, -33), (1, 31));
}

#[test]
fn new_file_header_is_8192_zero_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let (path, region) = new_region(dir.path());
    assert!(region.chunks().is_empty());
    assert_eq!(std::fs::read(&path).unwrap(), vec![0u8; 8192]);
    assert_eq!(region.path(), path);
    // An existing empty file (created, then killed before the header) is initialised too.
    let empty = dir.path().join("r.5.5.mca");
    std::fs::File::create(&empty).unwrap();
    RegionFile::open(&empty, false).unwrap();
    assert_eq!(std::fs::read(&empty).unwrap(), vec![0u8; 8192]);
}

#[test]
fn missing_and_too_short_files_are_open_errors() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("r.0.0.mca");
    assert!(matches!(RegionFile::open(&missing, false), Err(RegionError::Io { .. })));
    assert!(!missing.exists(), "open without create must not create the file");
    std::fs::write(&missing, [1u8; 100]).unwrap();
    match RegionFile::open(&missing, true) {
        Err(e @ RegionError::TooShort { len: 100, .. }) => assert!(e.to_string().contains("r.0.0.mca"), "{e}"),
        other => panic!("expected TooShort, got {:?}", other.err()),
    }
    assert_eq!(std::fs::read(&missing).unwrap(), vec![1u8; 100], "a short file is left alone");
}

#[test]
fn round_trip_many_chunks_in_a_negative_region() {
    let dir = tempfile::tempdir().unwrap();
    let pos = RegionPos::of_chunk(-40, -1000);
    assert_eq!(pos, RegionPos { x: -2, z: -32 });
    let path = dir.path().join(pos.file_name());
    assert!(path.ends_with("r.-2.-32.mca"));
    let chunk_of = |i: i32| (pos.x * 32 + i % 32, pos.z * 32 + i / 32);
    // Every chunk, with sizes from a fraction of a sector to several sectors.
    let content = |i: i32| {
        if i % 7 == 0 {
            noise(i as u64, 3000 + 900 * (i as usize % 20))
        } else {
            nbt_like(500 + 37 * i as usize)
        }
    };
    {
        let mut region = RegionFile::open(&path, true).unwrap();
        for i in 0..1024 {
            let (cx, cz) = chunk_of(i);
            assert_eq!(RegionPos::of_chunk(cx, cz), pos);
            let (lx, lz) = local(cx, cz);
            region.write(lx, lz, &compress(&content(i)), 1000 + i as u32).unwrap();
        }
        region.sync().unwrap();
        assert_eq!(region.chunks().len(), 1024);
    }
    assert_eq!(std::fs::metadata(&path).unwrap().len() % 4096, 0, "the file is padded to whole sectors");
    let mut region = RegionFile::open(&path, false).unwrap();
    assert_eq!(region.chunks().len(), 1024);
    for i in 0..1024 {
        let (lx, lz) = local(chunk_of(i).0, chunk_of(i).1);
        assert!(region.contains(lx, lz));
        assert_eq!(region.read(lx, lz).unwrap().unwrap(), content(i), "chunk {i}");
    }
    let mut stamp = [0u8; 4];
    std::fs::File::open(&path).unwrap().read_exact_at(&mut stamp, 4096 + 4 * 33).unwrap();
    assert_eq!(u32::from_be_bytes(stamp), 1033);
}

#[test]
fn reopen_sees_the_same_chunks_and_absent_ones_stay_absent() {
    let dir = tempfile::tempdir().unwrap();
    let (path, mut region) = new_region(dir.path());
    let written = [(0, 0), (31, 31), (5, 17), (17, 5)];
    for (n, &(lx, lz)) in written.iter().enumerate() {
        region.write(lx, lz, &compress(&nbt_like(100 * n + 1)), 1).unwrap();
    }
    drop(region);
    let mut region = RegionFile::open(&path, false).unwrap();
    let mut chunks = region.chunks();
    chunks.sort();
    let mut expected = written.to_vec();
    expected.sort();
    assert_eq!(chunks, expected);
    for (n, &(lx, lz)) in written.iter().enumerate() {
        assert_eq!(region.read(lx, lz).unwrap().unwrap(), nbt_like(100 * n + 1));
    }
    assert!(!region.contains(1, 1));
    assert_eq!(region.read(1, 1).unwrap(), None);
}

#[test]
fn rewrites_keep_other_chunks_and_reuse_freed_space() {
    let dir = tempfile::tempdir().unwrap();
    let (path, mut region) = new_region(dir.path());
    for lx in 0..20 {
        region.write(lx, 3, &payload(lx as u64, 1 + lx % 3), 0).unwrap();
    }
    let check_others = |region: &mut RegionFile| {
        for lx in (0..20).filter(|&lx| lx != 5) {
            assert_eq!(region.read(lx, 3).unwrap().unwrap(), decompress(&payload(lx as u64, 1 + lx % 3)));
        }
    };
    let base = std::fs::metadata(&path).unwrap().len();
    // Bigger, then smaller.
    for (n, sectors) in [6, 1].into_iter().enumerate() {
        let data = payload(100 + n as u64, sectors);
        region.write(5, 3, &data, 0).unwrap();
        assert_eq!(location(&path, 5, 3).1, sectors as u64);
        assert_eq!(region.read(5, 3).unwrap().unwrap(), decompress(&data));
        check_others(&mut region);
    }
    // The 6 sectors the big version used are free again: a 4-sector chunk goes there, not at the end.
    let len = std::fs::metadata(&path).unwrap().len();
    region.write(25, 3, &payload(200, 4), 0).unwrap();
    assert_eq!(std::fs::metadata(&path).unwrap().len(), len, "freed sectors are reused (first fit)");
    let mut settled = 0;
    for round in 0..100u64 {
        let data = payload(300 + round, 1 + round as usize % 6);
        region.write(5, 3, &data, round as u32).unwrap();
        assert_eq!(region.read(5, 3).unwrap().unwrap(), decompress(&data));
        if round == 10 {
            settled = std::fs::metadata(&path).unwrap().len();
        }
    }
    check_others(&mut region);
    let len = std::fs::metadata(&path).unwrap().len();
    // Appending every rewrite would add ~350 sectors; with reuse the file settles after a few
    // rounds (holes left by the 1–6 sector versions are filled again).
    assert_eq!(len, settled, "the file kept growing after the first rewrites");
    assert!(len - base <= 24 * 4096, "file grew by {} sectors over 100 rewrites", (len - base) / 4096);
    drop(region);
    let mut region = RegionFile::open(&path, false).unwrap();
    check_others(&mut region);
    assert_eq!(region.chunks().len(), 21);
}

fn decompress(zlib: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    ZlibDecoder::new(zlib).read_to_end(&mut out).unwrap();
    out
}

#[test]
fn a_write_killed_before_its_location_update_leaves_the_old_version() {
    let dir = tempfile::tempdir().unwrap();
    let (path, mut region) = new_region(dir.path());
    region.write(0, 0, &payload(1, 2), 0).unwrap();
    region.write(1, 0, &payload(2, 1), 0).unwrap();
    let mut old_entry = [0u8; 4];
    std::fs::File::open(&path).unwrap().read_exact_at(&mut old_entry, 0).unwrap();
    let (old_offset, old_count) = location(&path, 0, 0);
    region.write(0, 0, &payload(3, 3), 0).unwrap();
    let (new_offset, new_count) = location(&path, 0, 0);
    assert!(new_offset >= old_offset + old_count || new_offset + new_count <= old_offset, "wrote over the old sectors");
    drop(region);
    // The header as it was before the location update (the data write had happened).
    patch(&path, 0, &old_entry);
    let mut region = RegionFile::open(&path, false).unwrap();
    assert_eq!(region.read(0, 0).unwrap().unwrap(), decompress(&payload(1, 2)));
    assert_eq!(region.read(1, 0).unwrap().unwrap(), decompress(&payload(2, 1)));
}

#[test]
fn delete_frees_the_chunk_and_its_space() {
    let dir = tempfile::tempdir().unwrap();
    let (path, mut region) = new_region(dir.path());
    region.write(0, 0, &payload(1, 3), 0).unwrap();
    region.write(1, 0, &payload(2, 1), 0).unwrap();
    region.delete(0, 0).unwrap();
    region.delete(2, 2).unwrap();
    assert!(!region.contains(0, 0));
    assert_eq!(region.read(0, 0).unwrap(), None);
    assert_eq!(location(&path, 0, 0), (0, 0));
    let len = std::fs::metadata(&path).unwrap().len();
    region.write(3, 0, &payload(3, 3), 0).unwrap();
    assert_eq!(location(&path, 3, 0), (2, 3), "the deleted chunk's sectors are reused");
    assert_eq!(std::fs::metadata(&path).unwrap().len(), len);
    drop(region);
    let region = RegionFile::open(&path, false).unwrap();
    assert_eq!(region.chunks(), vec![(1, 0), (3, 0)]);
}

#[test]
fn oversized_chunk_is_invalid_input_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let (path, mut region) = new_region(dir.path());
    let err = region.write(4, 9, &vec![0u8; 256 * 4096], 0).unwrap_err();
    assert_eq!(err.kind(), std::io::ErrorKind::InvalidInput);
    assert!(err.to_string().contains("chunk 4, 9"), "{err}");
    assert!(!region.contains(4, 9));
    assert_eq!(std::fs::metadata(&path).unwrap().len(), 8192, "nothing was written");
    // The largest allowed size works.
    region.write(4, 9, &vec![7u8; 255 * 4096 - 5], 0).unwrap();
    assert_eq!(location(&path, 4, 9), (2, 255));
}

#[test]
fn garbage_data_is_corrupt() {
    let dir = tempfile::tempdir().unwrap();
    let path = three_chunks(dir.path());
    patch(&path, chunk_start(&path, 1, 0) + 5, &noise(9, 40));
    let mut region = RegionFile::open(&path, false).unwrap();
    assert!(region.contains(1, 0), "the header entry itself is fine");
    let reason = assert_corrupt(region.read(1, 0), "garbage");
    assert!(reason.contains("zlib"), "{reason}");
    assert_others_fine(&path, &[1]);
}

#[test]
fn length_zero_is_corrupt() {
    let dir = tempfile::tempdir().unwrap();
    let path = three_chunks(dir.path());
    patch(&path, chunk_start(&path, 1, 0), &0u32.to_be_bytes());
    assert_corrupt(RegionFile::open(&path, false).unwrap().read(1, 0), "length 0");
    assert_others_fine(&path, &[1]);
}

#[test]
fn length_beyond_its_sectors_is_corrupt_without_a_huge_allocation() {
    let dir = tempfile::tempdir().unwrap();
    let path = three_chunks(dir.path());
    patch(&path, chunk_start(&path, 1, 0), &4093u32.to_be_bytes());
    assert_corrupt(RegionFile::open(&path, false).unwrap().read(1, 0), "one byte too long");
    patch(&path, chunk_start(&path, 2, 0), &u32::MAX.to_be_bytes());
    assert_corrupt(RegionFile::open(&path, false).unwrap().read(2, 0), "4 GiB length");
    assert_others_fine(&path, &[1, 2]);
}

#[test]
fn unknown_unsupported_and_external_compression_are_corrupt() {
    let dir = tempfile::tempdir().unwrap();
    let path = three_chunks(dir.path());
    let mut region = RegionFile::open(&path, false).unwrap();
    for (byte, expect) in [(99u8, "unknown"), (4, "LZ4"), (0x82, ".mcc"), (0, "unknown")] {
        patch(&path, chunk_start(&path, 1, 0) + 4, &[byte]);
        let reason = assert_corrupt(region.read(1, 0), &format!("compression {byte}"));
        assert!(reason.contains(expect), "compression {byte}: {reason}");
    }
    drop(region);
    assert_others_fine(&path, &[1]);
}

#[test]
fn gzip_and_uncompressed_chunks_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let (path, mut region) = new_region(dir.path());
    let nbt = nbt_like(5000);
    let mut gzip = GzEncoder::new(Vec::new(), flate2::Compression::default());
    gzip.write_all(&nbt).unwrap();
    region.write(0, 0, &gzip.finish().unwrap(), 0).unwrap();
    region.write(1, 0, &nbt, 0).unwrap();
    patch(&path, chunk_start(&path, 0, 0) + 4, &[1]);
    patch(&path, chunk_start(&path, 1, 0) + 4, &[3]);
    let mut region = RegionFile::open(&path, false).unwrap();
    assert_eq!(region.read(0, 0).unwrap().unwrap(), nbt);
    assert_eq!(region.read(1, 0).unwrap().unwrap(), nbt);
}

#[test]
fn decompression_bombs_are_corrupt() {
    let dir = tempfile::tempdir().unwrap();
    let (_, mut region) = new_region(dir.path());
    region.write(0, 0, &compress(&vec![0u8; (MAX_DECOMPRESSED + 1) as usize]), 0).unwrap();
    let reason = assert_corrupt(region.read(0, 0), "bomb");
    assert!(reason.contains("more than"), "{reason}");
}

#[test]
fn location_past_eof_is_corrupt_and_its_space_is_not_trusted() {
    let dir = tempfile::tempdir().unwrap();
    let path = three_chunks(dir.path());
    let sectors = std::fs::metadata(&path).unwrap().len() / 4096;
    // Claims the sector just past the end, where the next append goes.
    set_location(&path, 9, 9, ((sectors as u32) << 8) | 1);
    set_location(&path, 8, 8, (1_000_000 << 8) | 255);
    let mut region = RegionFile::open(&path, false).unwrap();
    assert!(!region.contains(9, 9));
    assert!(!region.chunks().contains(&(9, 9)));
    assert_corrupt(region.read(9, 9), "past EOF");
    assert_corrupt(region.read(8, 8), "far past EOF");
    region.write(3, 0, &compress(&nbt_like(3333)), 0).unwrap();
    assert_eq!(location(&path, 3, 0).0, sectors, "appended over the bad entry's claim");
    drop(region);
    // The new chunk must not be seen as overlapping the stale entry after a reopen.
    let mut region = RegionFile::open(&path, false).unwrap();
    assert_eq!(region.read(3, 0).unwrap().unwrap(), nbt_like(3333));
    assert_eq!(region.read(9, 9).unwrap(), None, "the stale entry was cleared when its space was taken");
    assert_corrupt(region.read(8, 8), "still far past EOF");
    drop(region);
    assert_others_fine(&path, &[]);
}

#[test]
fn location_into_the_header_or_without_sectors_is_corrupt() {
    let dir = tempfile::tempdir().unwrap();
    let path = three_chunks(dir.path());
    set_location(&path, 9, 9, (1 << 8) | 1);
    set_location(&path, 9, 10, 5 << 8);
    let mut region = RegionFile::open(&path, false).unwrap();
    assert!(assert_corrupt(region.read(9, 9), "into header").contains("header"));
    assert_corrupt(region.read(9, 10), "no sectors");
    assert_others_fine(&path, &[]);
}

#[test]
fn overlapping_entries_are_both_corrupt_and_their_space_is_reused_safely() {
    let dir = tempfile::tempdir().unwrap();
    let path = three_chunks(dir.path());
    let (offset, count) = location(&path, 1, 0);
    set_location(&path, 7, 7, ((offset as u32) << 8) | count as u32);
    let mut region = RegionFile::open(&path, false).unwrap();
    assert!(!region.contains(1, 0) && !region.contains(7, 7));
    assert_corrupt(region.read(1, 0), "overlap, first");
    assert_corrupt(region.read(7, 7), "overlap, second");
    assert_eq!(region.chunks(), vec![(0, 0), (2, 0)]);
    // The contested sector is free: the next small chunk goes there.
    region.write(4, 0, &compress(&nbt_like(4444)), 0).unwrap();
    assert_eq!(location(&path, 4, 0).0, offset);
    drop(region);
    let mut region = RegionFile::open(&path, false).unwrap();
    assert_eq!(region.read(4, 0).unwrap().unwrap(), nbt_like(4444));
    assert_eq!(region.read(1, 0).unwrap(), None);
    assert_eq!(region.read(7, 7).unwrap(), None);
    drop(region);
    assert_others_fine(&path, &[1]);
}

#[test]
fn a_truncated_file_still_opens_and_other_chunks_read() {
    let dir = tempfile::tempdir().unwrap();
    let (path, mut region) = new_region(dir.path());
    region.write(0, 0, &payload(1, 1), 0).unwrap();
    region.write(1, 0, &payload(2, 2), 0).unwrap();
    region.write(2, 0, &payload(3, 3), 0).unwrap();
    drop(region);
    // A crash that lost the end of the last chunk: cut inside its second sector.
    let (offset, _) = location(&path, 2, 0);
    let file = OpenOptions::new().write(true).open(&path).unwrap();
    file.set_len(offset * 4096 + 4096 + 100).unwrap();
    let mut region = RegionFile::open(&path, false).unwrap();
    assert_eq!(region.read(0, 0).unwrap().unwrap(), decompress(&payload(1, 1)));
    assert_eq!(region.read(1, 0).unwrap().unwrap(), decompress(&payload(2, 2)));
    assert_corrupt(region.read(2, 0), "truncated");
    // Cut inside the last sector: the entry is within the file's sectors but its bytes are not.
    file.set_len(offset * 4096 + 3 * 4096 - 100).unwrap();
    let mut region = RegionFile::open(&path, false).unwrap();
    assert!(assert_corrupt(region.read(2, 0), "truncated in last sector").contains("truncated"));
    // Saving the chunk again repairs it.
    region.write(2, 0, &payload(4, 3), 0).unwrap();
    drop(region);
    let mut region = RegionFile::open(&path, false).unwrap();
    assert_eq!(region.read(2, 0).unwrap().unwrap(), decompress(&payload(4, 3)));
    assert_eq!(region.read(1, 0).unwrap().unwrap(), decompress(&payload(2, 2)));
}

#[test]
fn compress_round_trips_and_is_fast() {
    for data in [Vec::new(), b"x".to_vec(), nbt_like(40_000), noise(1, 40_000)] {
        assert_eq!(decompress(&compress(&data)), data);
    }
    let nbt = nbt_like(40_000);
    let runs = 200;
    let started = Instant::now();
    let mut size = 0;
    for _ in 0..runs {
        size = std::hint::black_box(compress(std::hint::black_box(&nbt))).len();
    }
    let micros = started.elapsed().as_secs_f64() * 1e6 / runs as f64;
    assert!(size < nbt.len() / 2, "NBT-like data should compress: {size} bytes");
    println!("compress: {} bytes -> {size} bytes in {micros:.1} µs", nbt.len());
}
