//! Files that declare far more data than they hold are refused without allocating what they
//! declare: every allocation made while reading stays within 4 × the file's size, plus the
//! fixed working memory of a decompressor (zlib's window and state: under 64 KiB).
//!
//! One test in this binary, so the allocation counter sees only the reader's allocations.

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use toposmooth::io::mesh::read_mesh;
use toposmooth::io::vtk::read_dataset;

/// The largest single allocation since the last reset.
static LARGEST: AtomicUsize = AtomicUsize::new(0);

struct Counting;

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LARGEST.fetch_max(new_size, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// A decompressor's fixed working memory (zlib's window and inflate state), whatever the
/// file: the 4 × rule applies to what the file's contents make us allocate.
const DECOMPRESSOR: usize = 64 << 10;

const GB: u64 = 1 << 30;

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("toposmooth-alloc-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn words(ws: &[u64]) -> Vec<u8> {
    ws.iter().flat_map(|w| w.to_le_bytes()).collect()
}

/// A `.vti` of 2^27 × 1 × 1 Float64 points (1 GB) whose appended raw data holds `block`.
fn vti(compressor: &str, block: &[u8]) -> Vec<u8> {
    vti_extent("0 134217727 0 0 0 0", compressor, block)
}

/// A `.vti` of Float64 points over `extent` whose appended raw data holds `block`.
fn vti_extent(extent: &str, compressor: &str, block: &[u8]) -> Vec<u8> {
    let mut f = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" \
         header_type=\"UInt64\"{compressor}>\n<ImageData WholeExtent=\"{extent}\" Origin=\"0 0 0\" \
         Spacing=\"1 1 1\">\n<Piece Extent=\"{extent}\">\n<PointData Scalars=\"f\">\n\
         <DataArray type=\"Float64\" Name=\"f\" format=\"appended\" offset=\"0\"/>\n</PointData>\n</Piece>\n\
         </ImageData>\n<AppendedData encoding=\"raw\">\n_"
    )
    .into_bytes();
    f.extend_from_slice(block);
    f.extend_from_slice(b"\n</AppendedData>\n</VTKFile>\n");
    f
}

fn cases() -> Vec<(&'static str, Vec<u8>)> {
    let zlib = |c: &str| format!(" compressor=\"{c}\"");
    let mut tiny_zlib = Vec::new();
    {
        use std::io::Write;
        let mut e = flate2::write::ZlibEncoder::new(&mut tiny_zlib, flate2::Compression::best());
        e.write_all(&[0u8; 4096]).unwrap();
        e.finish().unwrap();
    }
    let mut zlib_block = words(&[1, GB, GB, tiny_zlib.len() as u64]);
    zlib_block.extend_from_slice(&tiny_zlib);
    // 32768 × 32768 points (a proper 2D extent, so the extent is no reason to refuse it):
    // one zlib block declared 8 GB long that holds 4 KiB of zeros
    let mut zlib_8gb = words(&[1, 8 * GB, 8 * GB, tiny_zlib.len() as u64]);
    zlib_8gb.extend_from_slice(&tiny_zlib);
    let mut lz4_block = words(&[1, GB, GB, 12]);
    lz4_block.extend_from_slice(&[0x1f, 0, 1, 0, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff]);
    let mut tiny_xz = Vec::new();
    lzma_rs::xz_compress(&mut &[0u8; 64][..], &mut tiny_xz).unwrap();
    let mut lzma_block = words(&[1, GB, GB, tiny_xz.len() as u64]);
    lzma_block.extend_from_slice(&tiny_xz);
    let mut legacy = b"# vtk DataFile Version 3.0\nbig\nBINARY\nDATASET POLYDATA\nPOINTS 100000000 double\n".to_vec();
    legacy.extend_from_slice(&[0; 512]);
    let legacy_cells = b"# vtk DataFile Version 5.1\nbig\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\n\
        POLYGONS 100000001 300000000\nOFFSETS vtktypeint64\n0 3\nCONNECTIVITY vtktypeint64\n0 1 2\n"
        .to_vec();
    let vtu = b"<VTKFile type=\"UnstructuredGrid\" header_type=\"UInt64\"><UnstructuredGrid>\
        <Piece NumberOfPoints=\"100000000\" NumberOfCells=\"100000000\"><Points>\
        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">ABgNjwAAAAA=</DataArray>\
        </Points></Piece></UnstructuredGrid></VTKFile>"
        .to_vec();
    let ascii = b"<VTKFile type=\"ImageData\"><ImageData WholeExtent=\"0 9999 0 9999 0 0\"><Piece>\
        <PointData><DataArray type=\"Float64\" Name=\"f\" format=\"ascii\">1 2 3</DataArray></PointData>\
        </Piece></ImageData></VTKFile>"
        .to_vec();
    // 2^27 blocks of 8 bytes (1 GB in all), whose 2^27 compressed sizes are missing
    let mut zlib_sizes = words(&[1 << 27, 8, 8]);
    zlib_sizes.extend_from_slice(&[0; 64]);
    vec![
        ("raw.vti", vti("", &words(&[GB]))),
        ("over-the-cap.vti", vti("", &words(&[8 * GB]))),
        ("zlib.vti", vti(&zlib("vtkZLibDataCompressor"), &zlib_block)),
        ("zlib-many-blocks.vti", vti(&zlib("vtkZLibDataCompressor"), &zlib_sizes)),
        ("zlib-2d-8gb.vti", vti_extent("0 32767 0 32767 0 0", &zlib("vtkZLibDataCompressor"), &zlib_8gb)),
        ("lz4.vti", vti(&zlib("vtkLZ4DataCompressor"), &lz4_block)),
        ("lzma.vti", vti(&zlib("vtkLZMADataCompressor"), &lzma_block)),
        ("points.vtk", legacy),
        ("cells.vtk", legacy_cells),
        ("points.vtu", vtu),
        ("ascii.vti", ascii),
    ]
}

fn largest_while(read: impl FnOnce()) -> usize {
    LARGEST.store(0, Ordering::SeqCst);
    read();
    LARGEST.load(Ordering::SeqCst)
}

#[test]
fn declared_gigabytes_in_a_kilobyte_are_refused_within_four_times_the_file() {
    let d = dir();
    for (name, bytes) in cases() {
        assert!(bytes.len() < 1100, "{name}: {} bytes", bytes.len());
        let path: PathBuf = d.join(name);
        std::fs::write(&path, &bytes).unwrap();
        let mut message = String::new();
        let largest = largest_while(|| {
            let r = if name.ends_with(".vtk") || name.ends_with(".vtu") {
                read_mesh(Path::new(&path)).map(|_| ())
            } else {
                read_dataset(Path::new(&path)).map(|_| ())
            };
            message = r.expect_err(name).to_string();
        });
        eprintln!("{name}: {} bytes, largest allocation {largest}: {message}", bytes.len());
        let limit = 4 * bytes.len() + if name.contains("zlib") || name.contains("lzma") { DECOMPRESSOR } else { 0 };
        assert!(
            largest <= limit,
            "{name}: an allocation of {largest} bytes for a {}-byte file: {message}",
            bytes.len()
        );
        assert!(message.contains(name), "{name}: {message}");
    }
    std::fs::remove_dir_all(&d).unwrap();
}
