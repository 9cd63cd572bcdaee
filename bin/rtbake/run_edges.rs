//! `run smaa|mlaa` edge flags: `--edges luma|color|depth`, `--depth`, `--depth-threshold`, `--predication` (with
//! threshold/scale/strength), `--mask`; parsed into `runtime::smaa_edges::EdgeSettings`, files read and checked
//! here (size, channel count, finite depth: exit 2 naming the file) before any work.

use crate::cli::{usage, usage_msg};
use rtbake::io;
use rtbake::runtime::smaa_edges::{AaInputs, EdgeDetector, EdgeSettings, Predication, DEFAULT_DEPTH_THRESHOLD};
use std::path::{Path, PathBuf};

/// `--edges`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum EdgesArg {
    /// Luma of the sRGB-encoded colour (eq. 9.2), threshold 0.1; SMAA adds local contrast adaptation.
    Luma,
    /// Largest R, G, B difference of the sRGB-encoded colour, threshold 0.1 (finds edges between colours of equal
    /// luma); SMAA adds local contrast adaptation.
    Color,
    /// Depth differences of --depth against --depth-threshold (thesis Listing 9.1; SMAA's depth detector).
    Depth,
}

#[derive(clap::Args)]
pub struct EdgeArgs {
    /// Edge detector of the first pass.
    #[arg(long, value_enum, default_value = "luma")]
    edges: EdgesArg,
    /// Depth image for --edges depth and --predication: an EXR with ONE channel (e.g. Y), the input's size,
    /// finite values (any monotonic depth; thresholds are in its units).
    #[arg(long, value_name = "EXR")]
    depth: Option<PathBuf>,
    /// Threshold of --edges depth, in --depth's units (SMAA's SMAA_DEPTH_THRESHOLD, 0.1 · its colour threshold).
    #[arg(long, default_value_t = DEFAULT_DEPTH_THRESHOLD, allow_negative_numbers = true, value_name = "DEPTH")]
    depth_threshold: f32,
    /// Predicated thresholding of --edges luma|color from --depth: the threshold becomes
    /// scale · 0.1 · (1 − strength) across depth edges and scale · 0.1 elsewhere.
    #[arg(long)]
    predication: bool,
    /// Depth difference that counts as a predication edge, in --depth's units (> 0; SMAA's 0.01).
    #[arg(long, default_value_t = Predication::SMAA.threshold, allow_negative_numbers = true, value_name = "DEPTH")]
    predication_threshold: f32,
    /// Factor on the threshold with --predication, 1..=5 (SMAA's 2.0).
    #[arg(long, default_value_t = Predication::SMAA.scale, allow_negative_numbers = true)]
    predication_scale: f32,
    /// Decrease of the threshold across depth edges with --predication, 0..=1 (SMAA's 0.4).
    #[arg(long, default_value_t = Predication::SMAA.strength, allow_negative_numbers = true)]
    predication_strength: f32,
    /// Matte / stencil: an 8-bit one-channel (grey) PNG of the input's size; pixels below 128 are written exactly
    /// as they came in, pixels from 128 up are antialiased (and may blend with neighbours outside).
    #[arg(long, value_name = "PNG")]
    mask: Option<PathBuf>,
}

/// The validated settings and the images they read.
pub struct EdgeInputs {
    pub settings: EdgeSettings,
    depth: Option<Vec<f32>>,
    mask: Option<Vec<u8>>,
}

impl EdgeInputs {
    pub fn inputs(&self) -> AaInputs<'_> {
        AaInputs { depth: self.depth.as_deref(), mask: self.mask.as_deref() }
    }
}

impl EdgeArgs {
    /// The files these flags read (for the output-is-not-an-input check).
    pub fn files(&self) -> Vec<&Path> {
        self.depth.iter().chain(&self.mask).map(|p| p.as_path()).collect()
    }

    /// Validates the flags and reads --depth and --mask for a `w`×`h` input (exit 2 naming the flag or file).
    pub fn load(&self, w: u32, h: u32) -> anyhow::Result<EdgeInputs> {
        let detector = match self.edges {
            EdgesArg::Luma => EdgeDetector::Luma,
            EdgesArg::Color => EdgeDetector::Color,
            EdgesArg::Depth => EdgeDetector::Depth,
        };
        let predication = self.predication.then_some(Predication {
            threshold: self.predication_threshold,
            scale: self.predication_scale,
            strength: self.predication_strength,
        });
        let settings = EdgeSettings { detector, depth_threshold: self.depth_threshold, predication };
        settings.validate()?;
        let depth = match (&self.depth, settings.needs_depth()) {
            (None, true) => {
                return Err(usage_msg("--depth is required by --edges depth and by --predication (a one-channel EXR)"))
            }
            (Some(p), false) => {
                return Err(usage_msg(format!(
                    "--depth {}: read only by --edges depth and --predication; add one of them or drop --depth",
                    p.display()
                )))
            }
            (Some(p), true) => Some(read_depth(p, w, h)?),
            (None, false) => None,
        };
        let mask = self.mask.as_deref().map(|p| read_mask(p, w, h)).transpose()?;
        let out = EdgeInputs { settings, depth, mask };
        out.inputs().validate(w, h, &out.settings, out.mask.is_some())?;
        Ok(out)
    }
}

fn read_depth(path: &Path, w: u32, h: u32) -> anyhow::Result<Vec<f32>> {
    let name = path.display();
    let bytes = std::fs::read(path).map_err(|e| usage(anyhow::anyhow!("--depth {name}: {e}")))?;
    let img = io::exr::decode(&bytes, &name.to_string()).map_err(usage)?.0;
    if img.channels != 1 {
        return Err(usage_msg(format!("--depth {name}: must have one channel (depth), got {}", img.channels)));
    }
    if (img.width, img.height) != (w, h) {
        return Err(usage_msg(format!(
            "--depth {name}: is {}x{}, the input is {w}x{h} (sizes must match)",
            img.width, img.height
        )));
    }
    if let Some(i) = img.data.iter().position(|v| !v.is_finite()) {
        return Err(usage_msg(format!(
            "--depth {name}: must be finite; pixel ({}, {}) is {}",
            i % w as usize,
            i / w as usize,
            img.data[i]
        )));
    }
    Ok(img.data)
}

fn read_mask(path: &Path, w: u32, h: u32) -> anyhow::Result<Vec<u8>> {
    let name = path.display();
    let bytes = std::fs::read(path).map_err(|e| usage(anyhow::anyhow!("--mask {name}: {e}")))?;
    let img = match io::png::decode(&bytes, &name.to_string()).map_err(usage)? {
        io::png::DecodedPng::U8(img) => img,
        io::png::DecodedPng::U16(_) => {
            return Err(usage_msg(format!("--mask {name}: 16-bit PNG; expected 8-bit grey")))
        }
    };
    if img.channels != 1 {
        return Err(usage_msg(format!("--mask {name}: must have one channel (grey), got {}", img.channels)));
    }
    if (img.width, img.height) != (w, h) {
        return Err(usage_msg(format!(
            "--mask {name}: is {}x{}, the input is {w}x{h} (sizes must match)",
            img.width, img.height
        )));
    }
    Ok(img.data)
}
