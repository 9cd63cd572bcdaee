//! DDS as readers that follow the header flags see it: the DX10 pixel-format block says `DDPF_FOURCC` only.
//! Pillow (which follows the flags) decodes the RGBA8 files to exactly the `.bin` texels and, for the DXGI formats
//! it does not implement (R8, R8G8), refuses with an error instead of the all-black image it made before.
//!
//! Every 8-bit DDS also has a legacy-header copy (`*_dx9.dds`: `D3DFMT_L8`, `A8L8`, `A8R8G8B8`) for the readers
//! that refuse DX10 files. Checked with the readers themselves where installed: Pillow, ImageMagick (`convert`),
//! OpenImageIO (`oiiotool`); each must give the `.bin` texels exactly or refuse (never a wrong image). The `image`
//! crate's DDS decoder reads only DXT-compressed files, legacy or DX10, so it cannot serve these.

use crate::support::{baked_files_of_format, tool_available};

#[test]
fn every_baked_dds_has_a_fourcc_only_pixel_format() {
    let files = baked_files_of_format("dds");
    assert!(files.len() > 10);
    for (path, e) in files.into_iter().filter(|(p, _)| !is_legacy(p)) {
        let b = std::fs::read(&path).unwrap();
        let word = |at: usize| u32::from_le_bytes(b[at..at + 4].try_into().unwrap());
        assert_eq!(&b[84..88], b"DX10", "{}", e.path);
        assert_eq!(word(80), 0x4, "{}: pixel-format flags must be DDPF_FOURCC only", e.path);
        assert!(b[88..108].iter().all(|&v| v == 0), "{}: bit count and masks must be 0", e.path);
    }
}

fn is_legacy(p: &std::path::Path) -> bool {
    p.to_string_lossy().ends_with("_dx9.dds")
}

/// The legacy copies of a fresh bake (every 8-bit texture of these assets), written to `dir`: (path, .bin bytes,
/// channels).
fn legacy_copies(dir: &std::path::Path) -> Vec<(std::path::PathBuf, Vec<u8>, u32)> {
    let mut out = Vec::new();
    for name in ["smaa-area", "smaa-search", "mlaa-v1.3", "wrinkle-maps-example"] {
        let a = rtbake::bake::registry().into_iter().find(|a| a.name == name).unwrap();
        let files = a.run(&(a.default_params)()).unwrap();
        for f in files.iter().filter(|f| f.path.ends_with("_dx9.dds")) {
            let bin = files.iter().find(|b| b.path == f.path.replace("_dx9.dds", ".bin")).unwrap();
            let path = dir.join(f.path.replace('/', "_"));
            std::fs::write(&path, &f.bytes).unwrap();
            out.push((path, bin.bytes.clone(), bin.meta.channels));
        }
    }
    out
}

#[test]
fn every_8_bit_dds_has_a_legacy_copy_with_exact_d3d9_masks() {
    let files = baked_files_of_format("dds");
    let legacy: Vec<_> = files.iter().filter(|(p, _)| is_legacy(p)).collect();
    for (path, e) in files.iter().filter(|(p, e)| !is_legacy(p) && e.meta.sample_type.as_str() == "u8") {
        let copy = path.to_string_lossy().replace(".dds", "_dx9.dds");
        let (_, le) = legacy.iter().find(|(p, _)| p.to_string_lossy() == copy).unwrap_or_else(|| panic!("{copy}"));
        let b = std::fs::read(&copy).unwrap();
        let word = |at: usize| u32::from_le_bytes(b[at..at + 4].try_into().unwrap());
        let (name, flags, bits, masks) = rtbake::io::dds::legacy_format(e.meta.channels).unwrap();
        assert_eq!((word(80), word(84), word(88)), (flags, 0, bits), "{copy}: {name}");
        assert_eq!([word(92), word(96), word(100), word(104)], masks, "{copy}");
        assert!(le.meta.convention.contains(name), "{copy}: manifest names {name}");
        let (pf, w, h, data) = rtbake::io::dds::decode(&b, &copy).unwrap();
        assert_eq!((Some(pf), w, h), (e.meta.pixel_format, e.meta.width, e.meta.height), "{copy}");
        assert_eq!(data, std::fs::read(path.with_extension("bin")).unwrap(), "{copy}");
    }
    assert!(legacy.len() >= 10, "{} legacy copies", legacy.len());
}

const PILLOW_LEGACY: &str = r#"
import sys
from PIL import Image
im = Image.open(sys.argv[1])
im.load()
print(im.mode, "EQUAL" if im.tobytes() == open(sys.argv[2], "rb").read() else "DIFFERENT")
"#;

#[test]
fn pillow_reads_every_legacy_copy_as_the_bin_texels() {
    if !tool_available("Pillow legacy DDS check", "python3", &["-c", "import PIL"], "pip install pillow") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let copies = legacy_copies(dir.path());
    assert!(copies.len() >= 5);
    for (path, bin, channels) in &copies {
        let binp = path.with_extension("bin");
        std::fs::write(&binp, bin).unwrap();
        let out = std::process::Command::new("python3")
            .args(["-c", PILLOW_LEGACY, path.to_str().unwrap(), binp.to_str().unwrap()])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        let mode = ["L", "LA", "", "RGBA"][*channels as usize - 1];
        assert_eq!(
            text.trim(),
            format!("{mode} EQUAL"),
            "{}: {}",
            path.display(),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[test]
fn imagemagick_reads_legacy_l8_and_a8r8g8b8_exactly_and_never_misreads_a8l8() {
    if !tool_available("ImageMagick legacy DDS check", "convert", &["-version"], "apt-get install imagemagick") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut exact = 0;
    for (path, bin, channels) in legacy_copies(dir.path()) {
        let map = ["gray", "", "", "rgba"][channels as usize - 1];
        let out = std::process::Command::new("convert")
            .arg(&path)
            .args(["-depth", "8"])
            .arg(format!("{}:-", if map.is_empty() { "rgba" } else { map }))
            .output()
            .unwrap();
        if channels == 2 {
            // ImageMagick 6.9 has no luminance-alpha DDS reader: it must refuse, not decode something else.
            assert!(
                !out.status.success() || out.stdout.is_empty(),
                "{}: ImageMagick decoded A8L8; compare it with the .bin and tighten this test",
                path.display()
            );
            continue;
        }
        assert!(out.status.success(), "{}: {}", path.display(), String::from_utf8_lossy(&out.stderr));
        assert!(out.stdout == bin, "{}: ImageMagick's texels differ from the .bin", path.display());
        exact += 1;
    }
    assert!(exact >= 2, "no L8/A8R8G8B8 copy read");
}

#[test]
fn openimageio_reads_every_legacy_copy_as_the_bin_texels() {
    if !tool_available("OpenImageIO legacy DDS check", "oiiotool", &["--version"], "apt-get install openimageio-tools")
    {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let copies = legacy_copies(dir.path());
    for (path, bin, _) in &copies {
        let out = std::process::Command::new("oiiotool").args(["--info", "--dumpdata"]).arg(path).output().unwrap();
        assert!(out.status.success(), "{}: {}", path.display(), String::from_utf8_lossy(&out.stderr));
        // "    Pixel (x, y): v v … (floats)": the integer values before the parenthesis, in file order.
        let text = String::from_utf8_lossy(&out.stdout);
        let values: Vec<u8> = text
            .lines()
            .filter_map(|l| l.trim_start().strip_prefix("Pixel ("))
            .flat_map(|l| {
                let ints = l.split_once("): ").unwrap().1.split(" (").next().unwrap();
                ints.split_whitespace().map(|v| v.parse::<u8>().unwrap()).collect::<Vec<_>>()
            })
            .collect();
        assert!(values == *bin, "{}: OpenImageIO's texels differ from the .bin", path.display());
    }
}

const PILLOW_CHECK: &str = r#"
import sys
from PIL import Image
dds, raw = sys.argv[1], open(sys.argv[2], "rb").read()
try:
    im = Image.open(dds)
    im.load()
except NotImplementedError as e:
    print("REFUSED", e)
    sys.exit(0)
data = im.tobytes()
print("DECODED", im.mode, "EQUAL" if data == raw else "DIFFERENT", sum(data) == 0)
"#;

#[test]
fn pillow_reads_rgba8_dds_as_the_bin_texels_and_never_silently_black() {
    if !tool_available("Pillow DDS check", "python3", &["-c", "import PIL"], "pip install pillow") {
        return;
    }
    let mut decoded = 0;
    for (path, e) in baked_files_of_format("dds").into_iter().filter(|(p, _)| !is_legacy(p)) {
        let bin = path.with_extension("bin");
        let out = std::process::Command::new("python3")
            .args(["-c", PILLOW_CHECK, path.to_str().unwrap(), bin.to_str().unwrap()])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).to_string();
        assert!(out.status.success(), "{}: {text} {}", e.path, String::from_utf8_lossy(&out.stderr));
        match e.meta.pixel_format {
            Some(rtbake::io::PixelFormat::R8G8B8A8Unorm) => {
                assert!(text.starts_with("DECODED RGBA EQUAL"), "{}: {text}", e.path);
                decoded += 1;
            }
            _ => assert!(
                text.starts_with("REFUSED") || text.starts_with("DECODED") && text.contains("EQUAL"),
                "{}: {text}",
                e.path
            ),
        }
    }
    assert!(decoded >= 2, "no RGBA8 DDS decoded by Pillow");
}
