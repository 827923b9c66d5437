//! The field file: round trip, random access that touches only the view asked for, and
//! refusal of truncated, corrupted and hostile files with errors naming the chunk.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

mod common;

use std::sync::Mutex;

use frf_core::grid::Neighbour;
use frf_core::image::{FlowImage, GrayImage, Image, RgbImage};
use frf_reflectance::container::{ChunkKey, ChunkKind, FieldFile, ReadAt};
use frf_reflectance::flowcodec::{self, quant::LogQuantizer};
use frf_reflectance::store::encode_view;
use frf_reflectance::{FieldHeader, FieldWriter, ViewData};

const COLUMNS: usize = 4;

fn header() -> FieldHeader {
    let capture = common::tiny_capture(COLUMNS, 24, 32);
    FieldHeader::from_capture(&capture, &[0, 1], LogQuantizer::new(0.2, 12.0).unwrap(), 90).unwrap()
}

fn view(h: &FieldHeader, pose: u32, u: usize, v: usize) -> ViewData {
    let (w, hh) = (h.width as usize, h.height as usize);
    let seed = (pose as usize * 31 + u * 7 + v) as f32;
    let basis: Vec<RgbImage> = (0..h.conditions.len())
        .map(|c| {
            Image::from_fn(w, hh, |x, y| {
                let t = (x as f32 * 0.3 + y as f32 * 0.2 + seed + c as f32).sin() * 0.5 + 0.5;
                [t * 0.8, t * 0.5 + 0.1, 0.2 * (c as f32 + 1.0) / 26.0]
            })
        })
        .collect();
    let alpha: GrayImage = Image::from_fn(w, hh, |x, y| ((x + y) % 7) as f32 / 6.0);
    let mut flows: [Option<FlowImage>; 4] = Default::default();
    for n in Neighbour::ALL {
        if h.neighbour(u, v, n).is_some() {
            flows[n.index()] = Some(Image::from_fn(w, hh, |x, y| {
                if x < 2 {
                    [frf_core::flo::UNKNOWN; 2]
                } else {
                    [
                        x as f32 * 0.1 - 1.0 + seed * 0.01,
                        y as f32 * -0.05 + n.index() as f32,
                    ]
                }
            }));
        }
    }
    ViewData {
        basis,
        alpha,
        flows,
    }
}

fn write_field(path: &std::path::Path) -> FieldHeader {
    let h = header();
    write_views(path, h.clone());
    h
}

/// Writes every view of every pose of `h`.
fn write_views(path: &std::path::Path, h: FieldHeader) {
    let mut w = FieldWriter::create(path, h.clone()).unwrap();
    for pose in h.poses.iter().map(|p| p.pose).collect::<Vec<_>>() {
        for u in 0..h.columns {
            for v in 0..h.rows {
                w.add_view(
                    pose,
                    u,
                    v,
                    &encode_view(&h, pose, &view(&h, pose, u, v)).unwrap(),
                )
                .unwrap();
            }
        }
    }
    w.finish().unwrap();
}

#[test]
fn views_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("f.frf");
    let h = write_field(&path);
    let field = FieldFile::open(&path).unwrap();
    assert_eq!(field.header(), &h);
    let original = view(&h, 1, 3, 2);
    let back = field.view(1, 3, 2).unwrap();
    // Flows decode to exactly the dequantized values.
    for n in Neighbour::ALL {
        match (&original.flows[n.index()], &back.flows[n.index()]) {
            (Some(a), Some(b)) => {
                let q = &h.pose(1).unwrap().flow_quantizer;
                let expected =
                    flowcodec::dequantize(a.width(), a.height(), &flowcodec::quantize(a, q), q)
                        .unwrap();
                assert_eq!(b, &expected);
            }
            (None, None) => {}
            _ => panic!("flow {} present on one side only", n.name()),
        }
    }
    // The top row (v = 2) has no upward flow.
    assert!(back.flows[Neighbour::Up.index()].is_none());
    // Alpha is lossless to 16 bits; basis images close.
    for (a, b) in original.alpha.pixels().iter().zip(back.alpha.pixels()) {
        assert!((a - b).abs() <= 0.5 / 65535.0 + 1e-7);
    }
    for (a, b) in original.basis.iter().zip(&back.basis) {
        let err: f32 = a
            .pixels()
            .iter()
            .flatten()
            .zip(b.pixels().iter().flatten())
            .map(|(x, y)| (x - y).abs())
            .sum::<f32>()
            / (a.pixels().len() * 3) as f32;
        assert!(err < 0.01, "mean basis error {err}");
    }
    let stats = field.stats();
    assert_eq!((stats.poses, stats.views), (2, COLUMNS * 3));
    // 4 columns that wrap: 2 horizontal flows per view, and 4 vertical ones per column.
    assert_eq!(stats.flow_maps, 2 * (COLUMNS * 3 * 2 + COLUMNS * 4));
    assert_eq!(stats.basis_images, 2 * COLUMNS * 3 * 26);
    assert!(stats.flow_ratio_vs_8bit > 0.0 && stats.flow_ratio_vs_8bit < 1.0);
}

/// A source that records which byte ranges were read.
struct Recording {
    bytes: Vec<u8>,
    reads: Mutex<Vec<(u64, u64)>>,
}

impl ReadAt for Recording {
    fn read_exact_at(&self, offset: u64, buf: &mut [u8]) -> std::io::Result<()> {
        self.reads.lock().unwrap().push((offset, buf.len() as u64));
        self.bytes.read_exact_at(offset, buf)
    }
    fn size(&self) -> u64 {
        self.bytes.len() as u64
    }
}

#[test]
fn reading_one_view_touches_only_its_chunks() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("f.frf");
    write_field(&path);
    let bytes = std::fs::read(&path).unwrap();
    let field = FieldFile::from_source(
        &path,
        Recording {
            bytes,
            reads: Mutex::new(Vec::new()),
        },
    )
    .unwrap();
    let index_start = field.chunks().map(|c| c.offset + c.length).max().unwrap();
    let opening: Vec<(u64, u64)> = std::mem::take(&mut *field_reads(&field));
    // Opening reads the preamble, the footer and the index: nothing of the chunks.
    assert!(
        opening
            .iter()
            .all(|&(o, l)| o + l <= 16 || o >= index_start),
        "{opening:?}"
    );
    field.view(0, 2, 1).unwrap();
    let reads: Vec<(u64, u64)> = std::mem::take(&mut *field_reads(&field));
    let own: Vec<(u64, u64)> = field
        .chunks()
        .filter(|c| {
            (c.key.pose, c.key.u, c.key.v) == (0, 2, 1)
                && !matches!(c.key.kind, ChunkKind::Shadows | ChunkKind::Normals)
        })
        .map(|c| (c.offset, c.length))
        .collect();
    assert_eq!(own.len(), 2 + 4, "basis, alpha and 4 flows");
    // Its fitted normals are stored beside them, read only to relight a sun.
    assert!(field.normals(0, 2, 1).unwrap().is_some());
    for r in &reads {
        assert!(
            own.contains(r),
            "read {r:?} is not one of the view's chunks {own:?}"
        );
    }
    assert_eq!(reads.len(), own.len());
}

fn field_reads(field: &FieldFile<Recording>) -> std::sync::MutexGuard<'_, Vec<(u64, u64)>> {
    field.source().reads.lock().unwrap()
}

#[test]
fn truncated_and_corrupted_files_are_refused_naming_the_chunk() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("f.frf");
    write_field(&path);
    let good = std::fs::read(&path).unwrap();
    let field = FieldFile::open(&path).unwrap();
    let target = ChunkKey {
        pose: 1,
        u: 2,
        v: 0,
        kind: ChunkKind::Flow(Neighbour::Right),
    };
    let entry = *field.chunks().find(|c| c.key == target).unwrap();

    // Truncated anywhere: the footer is gone.
    for cut in [10, good.len() / 2, good.len() - 1] {
        std::fs::write(&path, &good[..cut]).unwrap();
        let err = FieldFile::open(&path).err().unwrap().to_string();
        assert!(
            err.contains("f.frf") && (err.contains("truncated") || err.contains("short")),
            "{err}"
        );
    }
    // One flipped bit inside a chunk: that chunk, and only it, is refused.
    let mut bad = good.clone();
    bad[(entry.offset + entry.length / 2) as usize] ^= 0x10;
    std::fs::write(&path, &bad).unwrap();
    let field = FieldFile::open(&path).unwrap();
    let err = field.view(1, 2, 0).unwrap_err().to_string();
    assert!(
        err.contains("flow right of pose 1 view (2, 0)") && err.contains("checksum"),
        "{err}"
    );
    field.view(1, 3, 0).unwrap();
    // A damaged index.
    let mut bad = good.clone();
    let n = bad.len();
    bad[n - 40] ^= 0xFF;
    std::fs::write(&path, &bad).unwrap();
    let err = FieldFile::open(&path).err().unwrap().to_string();
    assert!(err.contains("index"), "{err}");
    // Not a field at all.
    std::fs::write(&path, vec![7u8; 100]).unwrap();
    assert!(
        FieldFile::open(&path)
            .err()
            .unwrap()
            .to_string()
            .contains("magic")
    );
    // Asking for what is not there.
    std::fs::write(&path, &good).unwrap();
    let field = FieldFile::open(&path).unwrap();
    let e = field.view(5, 0, 0).unwrap_err().to_string();
    assert!(
        e.contains(&path.display().to_string())
            && e.contains("pose 5 is not in the field")
            && e.contains("it holds 0, 1"),
        "{e}"
    );
    let e = field.view(0, 9, 0).unwrap_err().to_string();
    assert!(
        e.contains(&path.display().to_string())
            && e.contains("view (9, 0)")
            && e.contains("4x3 grid"),
        "{e}"
    );
}

#[test]
fn an_unfinished_writer_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("f.frf");
    let h = header();
    {
        let mut w = FieldWriter::create(&path, h.clone()).unwrap();
        w.add_view(0, 0, 0, &encode_view(&h, 0, &view(&h, 0, 0, 0)).unwrap())
            .unwrap();
        // Dropped without finish(), as when a run is interrupted.
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    // Writing a view twice, or of a pose the header lacks, is refused.
    let mut w = FieldWriter::create(&path, h.clone()).unwrap();
    let enc = encode_view(&h, 0, &view(&h, 0, 0, 0)).unwrap();
    w.add_view(0, 0, 0, &enc).unwrap();
    let e = w.add_view(0, 0, 0, &enc).unwrap_err().to_string();
    assert!(
        e.contains(&path.display().to_string()) && e.contains("pose 0 view (0, 0) written twice"),
        "{e}"
    );
    let e = w.add_view(7, 0, 0, &enc).unwrap_err().to_string();
    assert!(
        e.contains(&path.display().to_string()) && e.contains("pose 7 is not in the field"),
        "{e}"
    );
    let mut wrong = view(&h, 0, 0, 0);
    wrong.basis.pop();
    let e = encode_view(&h, 0, &wrong).unwrap_err().to_string();
    assert!(
        e.contains("basis images per view") && e.contains("expected 26, got 25"),
        "{e}"
    );
    let e = encode_view(&h, 9, &view(&h, 0, 0, 0))
        .unwrap_err()
        .to_string();
    assert!(e.contains("pose 9 is not in the field"), "{e}");
}

/// Recomputes every chunk's CRC-32 and the index's, as a writer would have: damage made
/// to chunk bytes then reaches the chunk decoders instead of stopping at the checksum.
/// The index and footer are the file's tail (module docs of `container`), so they are
/// rewritten in place.
fn sealed(mut bytes: Vec<u8>) -> Vec<u8> {
    let footer = bytes.len() - 32;
    let word = |i: usize| u64::from_le_bytes(bytes[i..i + 8].try_into().unwrap()) as usize;
    let (at, len) = (word(footer), word(footer + 8));
    let tail = bytes[footer + 20..].to_vec(); // version and end magic
    let json = zstd::bulk::decompress(&bytes[at..at + len], 1 << 26).unwrap();
    let mut index: serde_json::Value = serde_json::from_slice(&json).unwrap();
    for c in index["chunks"].as_array_mut().unwrap() {
        let (o, l) = (
            c["offset"].as_u64().unwrap() as usize,
            c["length"].as_u64().unwrap() as usize,
        );
        c["crc32"] = crc32fast::hash(&bytes[o..o + l]).into();
    }
    let packed = zstd::bulk::compress(&serde_json::to_vec(&index).unwrap(), 3).unwrap();
    bytes.truncate(at);
    bytes.extend_from_slice(&packed);
    bytes.extend_from_slice(&(at as u64).to_le_bytes());
    bytes.extend_from_slice(&(packed.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&crc32fast::hash(&packed).to_le_bytes());
    bytes.extend_from_slice(&tail);
    bytes
}

#[test]
fn damaged_chunks_with_valid_checksums_are_decoded_or_refused_naming_the_chunk() {
    use proptest::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("f.frf");
    let h = write_field(&path);
    let good = std::fs::read(&path).unwrap();
    let entries: Vec<_> = FieldFile::open(&path).unwrap().chunks().copied().collect();
    let resealed =
        FieldFile::from_source(std::path::Path::new("resealed.frf"), sealed(good.clone())).unwrap();
    assert_eq!(resealed.chunks().copied().collect::<Vec<_>>(), entries);
    proptest!(ProptestConfig::with_cases(300), |(
        which in any::<prop::sample::Index>(),
        flips in proptest::collection::vec((any::<prop::sample::Index>(), 0u8..8), 1..4),
    )| {
        let entry = *which.get(&entries);
        let mut bytes = good.clone();
        for (at, bit) in &flips {
            bytes[entry.offset as usize + at.index(entry.length as usize)] ^= 1 << bit;
        }
        let bytes = sealed(bytes);
        let field = FieldFile::from_source(std::path::Path::new("damaged.frf"), bytes).unwrap();
        let key = entry.key;
        let read = if matches!(key.kind, ChunkKind::Shadows | ChunkKind::Hull) {
            field.shadows(key.pose).map(|_| ())
        } else {
            field.view(key.pose, key.u as usize, key.v as usize).map(|v| {
                assert_eq!(v.alpha.size(), (h.width as usize, h.height as usize));
            })
        };
        if let Err(e) = read {
            let e = e.to_string();
            prop_assert!(e.contains("damaged.frf") && e.contains(&key.to_string()), "{}", e);
        }
    });
}

#[test]
fn poses_written_apart_merge_into_one_field() {
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole.frf");
    let h = write_field(&whole);
    let mut parts = Vec::new();
    for pose in [1u32, 0] {
        let mut hp = h.clone();
        hp.poses.retain(|p| p.pose == pose);
        hp.description = format!("ingested with flow preset {pose}");
        hp.pose_mut(pose).unwrap().flow_quantizer =
            LogQuantizer::new(0.1 + pose as f32, 12.0).unwrap();
        let path = dir.path().join(format!("p{pose}.frf"));
        let mut w = FieldWriter::create(&path, hp.clone()).unwrap();
        for u in 0..hp.columns {
            for v in 0..hp.rows {
                w.add_view(
                    pose,
                    u,
                    v,
                    &encode_view(&hp, pose, &view(&hp, pose, u, v)).unwrap(),
                )
                .unwrap();
            }
        }
        w.finish().unwrap();
        parts.push(path);
    }
    let merged = dir.path().join("merged.frf");
    frf_reflectance::container::merge_fields(&parts, &merged).unwrap();
    let m = FieldFile::open(&merged).unwrap();
    assert_eq!(
        m.header().poses.iter().map(|p| p.pose).collect::<Vec<_>>(),
        vec![0, 1]
    );
    let single = FieldFile::open(&parts[0]).unwrap();
    assert_eq!(m.view(1, 2, 1).unwrap(), single.view(1, 2, 1).unwrap());
    assert_eq!(
        m.header().pose(1).unwrap().flow_quantizer,
        single.header().pose(1).unwrap().flow_quantizer
    );
    // Parts ingested with different settings keep the record of each.
    let said = &m.header().description;
    assert!(
        said.contains("poses [1] ingested with flow preset 1")
            && said.contains("poses [0] ingested with flow preset 0"),
        "{said}"
    );
    // The same pose twice is refused.
    let e =
        frf_reflectance::container::merge_fields(&[parts[0].clone(), parts[0].clone()], &merged)
            .unwrap_err()
            .to_string();
    assert!(
        e.contains(&parts[0].display().to_string()) && e.contains("pose 1 is in two parts"),
        "{e}"
    );
    // A part whose hulls were carved at another voxel is refused naming that alone.
    let other = dir.path().join("other.frf");
    let mut ho = FieldFile::open(&parts[1]).unwrap().header().clone();
    ho.hulls = Some(frf_reflectance::field::HullSpec {
        voxel_m: 0.005,
        misses: 1,
    });
    let w = FieldWriter::create(&other, ho).unwrap();
    w.finish().unwrap();
    let e = frf_reflectance::container::merge_fields(&[parts[0].clone(), other], &merged)
        .unwrap_err()
        .to_string();
    assert!(e.contains("the visual hulls") && e.contains("0.005"), "{e}");
    assert!(!e.contains("grid") && !e.contains("codec"), "{e}");
    // Parts must agree on the belt's speed: one that records another is refused naming
    // it; a merged field keeps the parts' speed.
    let faster = dir.path().join("faster.frf");
    let mut hs = FieldFile::open(&parts[1]).unwrap().header().clone();
    assert_eq!(hs.gait_speed_mps, None);
    hs.gait_speed_mps = Some(9.0);
    FieldWriter::create(&faster, hs.clone())
        .unwrap()
        .finish()
        .unwrap();
    let e = frf_reflectance::container::merge_fields(&[parts[0].clone(), faster.clone()], &merged)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the belt's speed") && e.contains("9 m/s") && e.contains("not recorded"),
        "{e}"
    );
    let slower = dir.path().join("slower.frf");
    let mut h0 = FieldFile::open(&parts[0]).unwrap().header().clone();
    h0.gait_speed_mps = Some(9.0);
    FieldWriter::create(&slower, h0).unwrap().finish().unwrap();
    frf_reflectance::container::merge_fields(&[slower, faster], &merged).unwrap();
    assert_eq!(
        FieldFile::open(&merged).unwrap().header().gait_speed_mps,
        Some(9.0)
    );
    // A negative speed is no speed.
    hs.gait_speed_mps = Some(-1.0);
    let e = FieldWriter::create(&dir.path().join("backward.frf"), hs)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("gait_speed_mps"), "{e}");
}

/// The fuzz targets start from small valid inputs (`fuzz/seeds/{container,huffman,images}`)
/// so that mutation reaches the decoders rather than the header checks. Each seed must be
/// valid; `FRF_WRITE_FUZZ_SEEDS=1` writes them afresh from the fixtures here.
#[test]
fn the_fuzz_seeds_are_valid_inputs() {
    let seeds = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/seeds");
    let container = seeds.join("container/tiny.frf");
    let with_pose_flows = seeds.join("container/pose_flows.frf");
    let flow = seeds.join("huffman/flow_map.bin");
    let (basis, planes) = (
        seeds.join("images/basis.bin"),
        seeds.join("images/planes.bin"),
    );
    let q = LogQuantizer::new(0.3, 20.0).unwrap(); // the huffman target's quantizer
    if std::env::var_os("FRF_WRITE_FUZZ_SEEDS").is_some() {
        let capture = common::tiny_capture(2, 8, 8);
        let h = FieldHeader::from_capture(&capture, &[0], q, 90).unwrap();
        for p in [&container, &flow, &basis] {
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        }
        write_views(&container, h.clone());
        write_pose_flow_seed(&with_pose_flows, &capture, q);
        let v = view(&h, 0, 0, 1);
        let f = v.flows.iter().flatten().next().unwrap();
        std::fs::write(&flow, flowcodec::encode(f, &q, true).unwrap()).unwrap();
        let b = frf_reflectance::imagecodec::encode_basis(&v.basis[..3], 90).unwrap();
        std::fs::write(&basis, b).unwrap();
        let p = frf_reflectance::imagecodec::encode_planes(&[v.alpha]).unwrap();
        std::fs::write(&planes, p).unwrap();
    }
    let field = FieldFile::open(&container).unwrap();
    let h = field.header().clone();
    for u in 0..h.columns {
        for v in 0..h.rows {
            field.view(0, u, v).unwrap();
        }
    }
    assert!(field.size() < 64 << 10, "seed of {} bytes", field.size());
    // The pose-flow seed: two poses whose flows lead to each other, every chunk whole.
    let field = FieldFile::open(&with_pose_flows).unwrap();
    assert!(field.header().check_pose_flows().is_ok());
    assert!(
        field
            .chunks()
            .any(|c| matches!(c.key.kind, ChunkKind::PoseFlow(_)))
    );
    assert!(field.verify(&|| {}).unwrap().damaged.is_empty());
    assert!(field.size() < 64 << 10, "seed of {} bytes", field.size());
    flowcodec::decode(&std::fs::read(&flow).unwrap(), &q).unwrap();
    frf_reflectance::imagecodec::decode_basis(&std::fs::read(&basis).unwrap()).unwrap();
    frf_reflectance::imagecodec::decode_planes(&std::fs::read(&planes).unwrap()).unwrap();
}

/// A field of poses 0 and 1 of `capture`, with pose-to-pose flows between them (the
/// views' own flows stand in for them): the fuzz target's seed for those chunks.
fn write_pose_flow_seed(
    path: &std::path::Path,
    capture: &frf_core::capture::Capture,
    q: LogQuantizer,
) {
    let mut h = FieldHeader::from_capture(capture, &[0, 1], q, 90).unwrap();
    for pose in [0, 1] {
        h.record_pose_flows(pose, &[0, 1]).unwrap();
    }
    let mut w = FieldWriter::create(path, h.clone()).unwrap();
    for pose in [0, 1] {
        for u in 0..h.columns {
            for v in 0..h.rows {
                let data = view(&h, pose, u, v);
                let between = [data.flows[0].clone(), data.flows[1].clone()];
                w.add_view(pose, u, v, &encode_view(&h, pose, &data).unwrap())
                    .unwrap();
                let flows = frf_reflectance::store::encode_pose_flows(&h, pose, &between).unwrap();
                w.add_view(pose, u, v, &flows).unwrap();
            }
        }
    }
    w.finish().unwrap();
}

/// `FieldFile::verify` (`frf info --check`) decodes every chunk of a whole field without a
/// complaint, and finds each damaged chunk of one with bytes changed in five places (its
/// error naming the first and counting the rest), where opening the field reads only the
/// index and succeeds.
#[test]
fn verify_reads_every_chunk_and_finds_each_damaged_one() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let whole = FieldFile::open(&root.join("fuzz/seeds/container/tiny.frf")).unwrap();
    let calls = std::cell::Cell::new(0);
    let v = whole.verify(&|| calls.set(calls.get() + 1)).unwrap();
    assert_eq!(v.chunks, whole.chunks().count());
    assert_eq!(calls.get(), v.chunks);
    assert!(v.damaged.is_empty(), "{:?}", v.damaged);
    assert!(v.error(whole.path()).is_none());

    let path = root.join("tests/bad/damaged_chunks.frf");
    let damaged = FieldFile::open(&path).unwrap();
    let v = damaged.verify(&|| {}).unwrap();
    // The chunks holding a byte that differs from the whole field's, each named once.
    let (a, b) = (
        std::fs::read(whole.path()).unwrap(),
        std::fs::read(&path).unwrap(),
    );
    let changed: Vec<u64> = (0..a.len() as u64)
        .filter(|&i| a[i as usize] != b[i as usize])
        .collect();
    assert_eq!(changed.len(), 5, "the corpus file changes five bytes");
    let mut hit: Vec<String> = damaged
        .chunks()
        .filter(|c| {
            changed
                .iter()
                .any(|&i| (c.offset..c.offset + c.length).contains(&i))
        })
        .map(|c| c.key.to_string())
        .collect();
    hit.sort();
    let mut found: Vec<String> = v.damaged.iter().map(|(k, _)| k.clone()).collect();
    found.sort();
    assert_eq!(found, hit, "{:?}", v.damaged);
    let said = v.error(&path).unwrap().to_string();
    assert!(said.contains(&v.damaged[0].0), "{said}");
    assert!(
        said.contains(&format!("{} more of the", v.damaged.len() - 1)),
        "{said}"
    );
}
