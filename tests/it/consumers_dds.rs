//! DDS as readers that follow the header flags see it: the DX10 pixel-format block says `DDPF_FOURCC` only.
//! Pillow (which follows the flags) decodes the RGBA8 files to exactly the `.bin` texels and, for the DXGI formats
//! it does not implement (R8, R8G8), refuses with an error instead of the all-black image it made before.

use crate::support::{baked_files_of_format, tool_available};

#[test]
fn every_baked_dds_has_a_fourcc_only_pixel_format() {
    let files = baked_files_of_format("dds");
    assert!(files.len() > 10);
    for (path, e) in files {
        let b = std::fs::read(&path).unwrap();
        let word = |at: usize| u32::from_le_bytes(b[at..at + 4].try_into().unwrap());
        assert_eq!(&b[84..88], b"DX10", "{}", e.path);
        assert_eq!(word(80), 0x4, "{}: pixel-format flags must be DDPF_FOURCC only", e.path);
        assert!(b[88..108].iter().all(|&v| v == 0), "{}: bit count and masks must be 0", e.path);
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
    for (path, e) in baked_files_of_format("dds") {
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
