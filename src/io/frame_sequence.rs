//! A directory of numbered frames, the input of the SMAA modes (thesis ch. 10: S2x, T2x, 4x):
//! `frame_NNNN.png` (or `frame_NNNN_s0.png` + `frame_NNNN_s1.png` for two spatial samples) and
//! `frame_NNNN_velocity.exr`, N = 0000, 0001, … consecutive from 0000.
//!
//! Everything is read and checked before any work: 8-bit RGB(A) colour, 2 to 4 velocity channels (R = x right,
//! G = y down, pixels per frame), finite velocities, one size for all files, and no gap in the numbering (a
//! `frame_0002.png` with no `frame_0001.png` is refused naming the missing frame, never silently ignored).
//! Errors are [`InvalidInput`] whose `param` is the file or directory at fault; the caller names its flag.

use crate::error::InvalidInput;
use crate::image_buf::Image;
use std::path::Path;

/// One frame: its colour samples as RGBA8 (sRGB-encoded, row-major) and its velocity, two f32 per pixel.
pub struct SequenceFrame {
    pub samples: Vec<Vec<u8>>,
    pub velocity_px: Vec<f32>,
}

/// A checked frame sequence.
pub struct FrameSequence {
    pub width: u32,
    pub height: u32,
    pub frames: Vec<SequenceFrame>,
}

/// `frame_NNNN`.
pub fn frame_name(n: u64) -> String {
    format!("frame_{n:04}")
}

/// The colour file names of frame `n` for `samples_per_frame` (1 or 2) samples.
pub fn colour_names(n: u64, samples_per_frame: usize) -> Vec<String> {
    match samples_per_frame {
        1 => vec![format!("{}.png", frame_name(n))],
        _ => (0..samples_per_frame).map(|s| format!("{}_s{s}.png", frame_name(n))).collect(),
    }
}

fn bad(path: &Path, msg: impl Into<String>) -> InvalidInput {
    InvalidInput::new(path.display().to_string(), msg)
}

/// The frame numbers present in `dir` (any `frame_NNNN…` file), sorted.
fn numbers_present(dir: &Path) -> Result<Vec<u64>, InvalidInput> {
    let rd = std::fs::read_dir(dir).map_err(|e| bad(dir, format!("cannot list: {e}")))?;
    let mut ns: Vec<u64> = rd
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            let digits = name.strip_prefix("frame_")?.get(..4)?;
            let rest = &name["frame_".len() + 4..];
            let known = [".png", "_s0.png", "_s1.png", "_velocity.exr"].contains(&rest);
            (known && digits.bytes().all(|b| b.is_ascii_digit())).then(|| digits.parse().ok()).flatten()
        })
        .collect();
    ns.sort_unstable();
    ns.dedup();
    Ok(ns)
}

fn to_rgba8(img: &Image<u8>) -> Vec<u8> {
    let ch = img.channels as usize;
    img.data.chunks(ch).flat_map(|p| if ch == 3 { [p[0], p[1], p[2], 255] } else { [p[0], p[1], p[2], p[3]] }).collect()
}

/// Reads and checks the whole sequence in `dir` for `samples_per_frame` colour samples per frame; `mode` names
/// the SMAA mode in messages.
pub fn read_frame_sequence(dir: &Path, samples_per_frame: usize, mode: &str) -> Result<FrameSequence, InvalidInput> {
    if !dir.is_dir() {
        return Err(bad(dir, "not a directory"));
    }
    let present = numbers_present(dir)?;
    let Some(&last) = present.last() else {
        return Err(bad(
            dir,
            format!(
                "no {} found (see `rtbake run smaa --help` for the names)",
                colour_names(0, samples_per_frame).join(" / ")
            ),
        ));
    };
    if let Some(missing) = (0..=last).find(|n| present.binary_search(n).is_err()) {
        return Err(bad(
            &dir.join(colour_names(missing, samples_per_frame)[0].as_str()),
            format!(
                "is missing: frames must be numbered consecutively from 0000, and this directory has frames up to \
                 {} (add frame {missing:04} or renumber the frames after it)",
                frame_name(last)
            ),
        ));
    }
    let mut size: Option<(u32, u32, String)> = None;
    let mut check_size = |path: &Path, w: u32, h: u32| -> Result<(), InvalidInput> {
        match &size {
            None => size = Some((w, h, path.display().to_string())),
            Some((w0, h0, first)) if (*w0, *h0) != (w, h) => {
                return Err(bad(path, format!("is {w}x{h}, but {first} is {w0}x{h0} (all frames must have one size)")))
            }
            _ => {}
        }
        Ok(())
    };
    let mut frames = Vec::with_capacity(present.len());
    for n in 0..=last {
        let mut samples = Vec::new();
        for name in colour_names(n, samples_per_frame) {
            let path = dir.join(&name);
            if !path.is_file() {
                return Err(bad(&path, format!("is missing (SMAA {mode} needs it)")));
            }
            let bytes = std::fs::read(&path).map_err(|e| bad(&path, e.to_string()))?;
            let img =
                match super::png::decode(&bytes, &path.display().to_string()).map_err(|e| bad(&path, e.to_string()))? {
                    super::png::DecodedPng::U8(img) => img,
                    super::png::DecodedPng::U16(_) => return Err(bad(&path, "16-bit PNG; expected 8-bit sRGB")),
                };
            if !(img.channels == 3 || img.channels == 4) {
                return Err(bad(&path, format!("{} channel(s); colour frames must be RGB or RGBA", img.channels)));
            }
            check_size(&path, img.width, img.height)?;
            samples.push(to_rgba8(&img));
        }
        let vpath = dir.join(format!("{}_velocity.exr", frame_name(n)));
        if !vpath.is_file() {
            return Err(bad(&vpath, "velocity is missing"));
        }
        let bytes = std::fs::read(&vpath).map_err(|e| bad(&vpath, e.to_string()))?;
        let v = super::exr::decode(&bytes, &vpath.display().to_string()).map_err(|e| bad(&vpath, e.to_string()))?.0;
        if !(2..=4).contains(&v.channels) {
            return Err(bad(
                &vpath,
                format!("{} channel(s); velocity needs 2 to 4 (R = x, G = y, pixels per frame)", v.channels),
            ));
        }
        check_size(&vpath, v.width, v.height)?;
        let velocity_px: Vec<f32> = v.data.chunks(v.channels as usize).flat_map(|p| [p[0], p[1]]).collect();
        if let Some(i) = velocity_px.iter().position(|x| !x.is_finite()) {
            let px = i / 2;
            return Err(bad(
                &vpath,
                format!(
                    "velocity must be finite, pixel ({}, {}) is {}",
                    px % v.width as usize,
                    px / v.width as usize,
                    velocity_px[i]
                ),
            ));
        }
        frames.push(SequenceFrame { samples, velocity_px });
    }
    let (width, height, _) = size.expect("at least frame 0000 was read");
    Ok(FrameSequence { width, height, frames })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gap_in_the_numbering_names_the_missing_frame() {
        let t = tempfile::tempdir().unwrap();
        for n in ["0000", "0002", "0003"] {
            std::fs::write(t.path().join(format!("frame_{n}.png")), b"not read before the gap check").unwrap();
        }
        let e = read_frame_sequence(t.path(), 1, "t2x").err().expect("refused");
        assert!(e.param.ends_with("frame_0001.png"), "{e}");
        assert!(e.message.contains("frames up to frame_0003"), "{e}");
    }

    #[test]
    fn an_empty_directory_names_the_expected_files() {
        let t = tempfile::tempdir().unwrap();
        let e = read_frame_sequence(t.path(), 2, "s2x").err().expect("refused");
        assert!(e.message.contains("frame_0000_s0.png / frame_0000_s1.png"), "{e}");
    }
}
