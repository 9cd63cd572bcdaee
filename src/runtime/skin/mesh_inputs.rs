//! The hemoglobin rig evaluated in texture space on the mesh path of `run skin` (thesis §7.6, eq. 7.6; Jimenez et
//! al., "A Practical Appearance Model for Dynamic Facial Color", SIGGRAPH Asia 2010):
//!
//! ```text
//! H(uv) = g · (Σᵢ wᵢ·bias_i(uv) + H0(uv) · Σᵢ wᵢ·scale_i(uv)),   Σᵢ wᵢ = 1                 (eq. 7.6)
//! g     = 1 + Σ_s a_s·(g_s − 1),   a_s ∈ [0, 1]   (global states, §7.7: anger g = 1.27, fear g = 0.81)
//! ```
//!
//! The rig's scale/bias maps and H0 are texture-space maps, so they are read at the **mesh's** texture
//! coordinates (the G-buffer's uv), not at the screen uv the procedural demo's skin-inputs pass uses
//! ([`crate::runtime::skin::inputs`]). Every map is read bilinearly (texel centres at (i + 0.5)/size, clamp to edge), as the
//! rig's `sampling` field states. The pass writes H per covered pixel; `run skin` hands it to the skin-inputs pass
//! as its hemoglobin with a neutral (scale 1, bias 0) rig, so the albedo LUT lookup of eq. 7.7 is unchanged. The
//! thesis applies the global state factor g to the whole hemoglobin map after the blend, as
//! [`crate::facial::hemoglobin_rig::evaluate`] does.
//!
//! One compute dispatch over flat f32 buffers (`skin/mesh_inputs.wgsl`, via `compute_chain`): on its own
//! ([`hemoglobin_at_uv`], one submission and read-back), or recorded into a frame's command encoder with H written
//! into the skin-inputs maps on the device (`record_into_skin_maps`, the screen-space frame of
//! `shade_frame`). The CPU twin is [`crate::runtime::skin::mesh_inputs_cpu`].

use crate::error::InvalidInput;
use crate::image_buf::Image;
use crate::runtime::compute_chain::{self, Buffer, Stage};
use crate::runtime::gpu;
use crate::runtime::loader::BakedRig;
use crate::runtime::skin::inputs::{RigScaleBiasMaps, MAX_RIG_TARGETS};
use crate::runtime::RuntimeError;

/// The parameter that sets a [`RigPose`] (its flag is in the CLI's table).
pub const RIG_WEIGHTS_PARAM: &str = "rig_weights";

/// The rig's pose: one weight per target (eq. 7.6, summing to 1) and the global state factor g.
#[derive(Clone, Debug, PartialEq)]
pub struct RigPose {
    pub weights: Vec<f32>,
    pub global_scale: f32,
}

impl RigPose {
    /// Weight 1 on the neutral target (index 0), g = 1: H = bias₀ + H0 = Hn.
    pub fn neutral(targets: usize) -> Self {
        let mut weights = vec![0.0; targets.max(1)];
        weights[0] = 1.0;
        RigPose { weights, global_scale: 1.0 }
    }

    /// Parses `{"target": weight, …, "global": {"anger": a, "fear": f}}` against the rig's target `names` and its
    /// `global_scales` (`--rig-weights`): target weights finite and summing to 1 ± 1e-3 (unnamed targets 0);
    /// global weights a ∈ [0, 1], each naming one of the rig's global states; g = 1 + Σ a·(g_state − 1).
    pub fn from_json(
        json: &serde_json::Value,
        names: &[String],
        global_scales: &[(String, f64)],
    ) -> Result<Self, InvalidInput> {
        let param = RIG_WEIGHTS_PARAM;
        let obj = json.as_object().ok_or_else(|| {
            InvalidInput::new(param, "must be a JSON object {\"target\": weight, ..., \"global\": {\"anger\": a}}")
        })?;
        let mut weights = vec![0.0f32; names.len()];
        let mut global_scale = 1.0f64;
        for (key, v) in obj {
            if key == "global" {
                let g = v.as_object().ok_or_else(|| {
                    InvalidInput::new(param, "\"global\" must be an object {\"anger\": a, \"fear\": f}, a in [0, 1]")
                })?;
                for (state, a) in g {
                    let (_, factor) = global_scales.iter().find(|(n, _)| n == state).ok_or_else(|| {
                        let known: Vec<&str> = global_scales.iter().map(|(n, _)| n.as_str()).collect();
                        InvalidInput::new(param, format!("unknown global state {state:?}; the rig has {known:?}"))
                    })?;
                    let a = a.as_f64().filter(|a| (0.0..=1.0).contains(a)).ok_or_else(|| {
                        InvalidInput::new(param, format!("global weight of {state:?} must be in [0, 1], got {a}"))
                    })?;
                    global_scale += a * (factor - 1.0);
                }
                continue;
            }
            let i = names.iter().position(|n| n == key).ok_or_else(|| {
                InvalidInput::new(param, format!("unknown target {key:?}; the rig has {names:?} and \"global\""))
            })?;
            let w = v.as_f64().filter(|w| w.is_finite()).ok_or_else(|| {
                InvalidInput::new(param, format!("weight of {key:?} must be a finite number, got {v}"))
            })?;
            weights[i] = w as f32;
        }
        let sum: f32 = weights.iter().sum();
        if (sum - 1.0).abs() > 1e-3 {
            return Err(InvalidInput::new(param, format!("target weights must sum to 1 (eq. 7.6), got {sum}")));
        }
        Ok(RigPose { weights, global_scale: global_scale as f32 })
    }

    /// As [`RigPose::from_json`] with the targets and global states of a baked rig.
    pub fn for_baked_rig(json: &serde_json::Value, rig: &BakedRig) -> Result<Self, InvalidInput> {
        Self::from_json(json, &rig.names, &rig.global_scales)
    }
}

/// The maps of eq. 7.6 in texture space and the pose to evaluate.
#[derive(Clone, Copy, Debug)]
pub struct RigAtUv<'a> {
    pub rig: &'a RigScaleBiasMaps,
    /// Mean-free neutral hemoglobin H0 (eq. 7.4), one channel.
    pub h0: &'a Image<f32>,
    pub pose: &'a RigPose,
}

impl RigAtUv<'_> {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        self.rig.validate()?;
        if self.pose.weights.len() != self.rig.targets.len() || self.rig.targets.len() > MAX_RIG_TARGETS {
            return Err(InvalidInput::new(
                RIG_WEIGHTS_PARAM,
                format!(
                    "needs one weight per rig target ({}), got {}",
                    self.rig.targets.len(),
                    self.pose.weights.len()
                ),
            ));
        }
        if self.h0.channels != 1 || self.h0.width == 0 || self.h0.height == 0 {
            return Err(InvalidInput::new("hemoglobin rig", "H0 must be a non-empty one-channel map"));
        }
        if !self.pose.global_scale.is_finite() || self.pose.global_scale < 0.0 {
            return Err(InvalidInput::new(RIG_WEIGHTS_PARAM, "the global scale must be finite and >= 0"));
        }
        Ok(())
    }
}

/// The largest per-pixel buffer [`hemoglobin_at_uv`] allocates for a `width`×`height` G-buffer, bytes: uv and
/// coverage, one vec4 of f32 per pixel (the rig and H₀ maps are the baked maps, independent of the frame).
pub fn largest_buffer_bytes(width: u32, height: u32) -> u64 {
    compute_chain::vec4_per_pixel_bytes(width, height)
}

const SOURCE: &str =
    concat!(include_str!("pixel_frame.wgsl"), include_str!("bilinear_taps.wgsl"), include_str!("mesh_inputs.wgsl"));

/// The pass's uniform block and the rig's targets, checked.
fn rig_inputs(
    width: u32,
    height: u32,
    maps: &RigAtUv<'_>,
) -> Result<(compute_chain::MapParams, Vec<f32>), RuntimeError> {
    maps.validate()?;
    let mut w = [[0.0f32; 4]; 2];
    for (i, v) in maps.pose.weights.iter().enumerate() {
        w[i / 4][i % 4] = *v;
    }
    let params = compute_chain::MapParams {
        size: [width as f32, height as f32, maps.rig.width as f32, maps.rig.height as f32],
        cfg: [maps.h0.width as f32, maps.h0.height as f32, maps.rig.targets.len() as f32, maps.pose.global_scale],
        weights: w,
    };
    let rig: Vec<f32> = maps.rig.targets.iter().flatten().flatten().copied().collect();
    Ok((params, rig))
}

/// [`rig_inputs`] and the (u, v, covered, 0) per pixel the pass reads, checked.
fn pass_inputs(
    width: u32,
    height: u32,
    uv: &[[f32; 2]],
    covered: &[bool],
    maps: &RigAtUv<'_>,
) -> Result<(compute_chain::MapParams, Vec<f32>, Vec<f32>), RuntimeError> {
    let (params, rig) = rig_inputs(width, height, maps)?;
    let n = (width * height) as usize;
    if uv.len() != n || covered.len() != n {
        return Err(InvalidInput::new("mesh uv", format!("needs {width}x{height} texture coordinates")).into());
    }
    let uvc: Vec<f32> = uv.iter().zip(covered).flat_map(|(t, &c)| [t[0], t[1], c as u8 as f32, 0.0]).collect();
    Ok((params, uvc, rig))
}

/// Per pixel of a `width`×`height` frame, (u, v, covered) → H (0 where not covered), on the GPU.
pub fn hemoglobin_at_uv(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    width: u32,
    height: u32,
    uv: &[[f32; 2]],
    covered: &[bool],
    maps: &RigAtUv<'_>,
) -> Result<Vec<f32>, RuntimeError> {
    let (params, uvc, rig) = pass_inputs(width, height, uv, covered, maps)?;
    let out = compute_chain::run(
        device,
        queue,
        "mesh skin inputs",
        SOURCE,
        bytemuck::bytes_of(&params),
        &[
            Buffer::Data(bytemuck::cast_slice(&uvc)),
            Buffer::Data(bytemuck::cast_slice(&rig)),
            Buffer::Data(bytemuck::cast_slice(&maps.h0.data)),
            Buffer::Zeroed(4 * (width * height) as u64),
        ],
        &[Stage::new("main", compute_chain::groups_8x8(width, height))],
        3,
    )?;
    Ok(bytemuck::cast_slice(&out).to_vec())
}

/// Records the pass into `enc`, a frame's command encoder, with H written into the hemoglobin channel of
/// `skin_maps` (the skin-inputs maps, `width`×`height` `Rgba32Float`, (Cm, H0, thickness mm, 0)), whose other
/// channels are `texels` (row-major, one per pixel): no submission and no read-back of its own.
#[allow(clippy::too_many_arguments)]
pub(crate) fn record_into_skin_maps(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    width: u32,
    height: u32,
    uv: &[[f32; 2]],
    covered: &[bool],
    maps: &RigAtUv<'_>,
    texels: &[[f32; 4]],
    skin_maps: &wgpu::Texture,
) -> Result<(), RuntimeError> {
    let (_, uvc, _) = pass_inputs(width, height, uv, covered, maps)?;
    let n = (width * height) as usize;
    if texels.len() != n || (skin_maps.width(), skin_maps.height()) != (width, height) {
        return Err(InvalidInput::new("skin maps", format!("must be {width}x{height}")).into());
    }
    // The skin maps in a texture copy's padded rows.
    let stride = (gpu::padded_row_bytes(skin_maps) / 16) as usize;
    let mut padded = vec![[0.0f32; 4]; stride * height as usize];
    for (row, src) in padded.chunks_exact_mut(stride).zip(texels.chunks_exact(width as usize)) {
        row[..width as usize].copy_from_slice(src);
    }
    let what = "mesh skin inputs";
    let uvc_buf = compute_chain::storage_buffer(device, what, 4 * uvc.len() as u64, Some(bytemuck::cast_slice(&uvc)));
    let bytes = 16 * padded.len() as u64;
    let maps_buf = compute_chain::storage_buffer(device, what, bytes, Some(bytemuck::cast_slice(&padded)));
    record_into_skin_map_buffer(device, enc, (width, height), maps, &uvc_buf, &maps_buf, stride as u32)?;
    gpu::encode_buffer_to_texture(enc, &maps_buf, 0, skin_maps);
    Ok(())
}

/// The rig's scale/bias texels and H0 uploaded per (device, content hash): a command uses one rig.
static RIG_TABLES: gpu::Kept<(wgpu::Device, u64), [wgpu::Buffer; 2]> = gpu::Kept::new(8);

/// A 64-bit hash of the rig's flattened texels and H0 (small maps: hashing them costs far less than an upload).
fn tables_key(rig: &[f32], h0: &[f32]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (rig.len(), h0.len()).hash(&mut h);
    rig.iter().chain(h0).for_each(|v| v.to_bits().hash(&mut h));
    h.finish()
}

/// Records the pass into `enc` over GPU buffers: (u, v, covered, 0) per pixel of the `size` frame in `uvc`, H
/// written into the hemoglobin channel of `skin_maps` (vec4 texels, rows of `stride` texels).
pub(crate) fn record_into_skin_map_buffer(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    (width, height): (u32, u32),
    maps: &RigAtUv<'_>,
    uvc: &wgpu::Buffer,
    skin_maps: &wgpu::Buffer,
    stride: u32,
) -> Result<(), RuntimeError> {
    let (params, rig) = rig_inputs(width, height, maps)?;
    let what = "mesh skin inputs";
    let h0: &[u8] = bytemuck::cast_slice(&maps.h0.data);
    let n = width as u64 * height as u64;
    let sizes = [uvc.size(), 4 * rig.len() as u64, h0.len() as u64, 4 * n, skin_maps.size()];
    compute_chain::check_buffers(device, what, &sizes)?;
    // The rig and H0 uploaded once per device and content while kept; H per pixel from the frame pool (`main`
    // writes every pixel's before `into_skin_maps` reads it).
    let [rig_buf, h0_buf] = RIG_TABLES.get_or_insert_with((device.clone(), tables_key(&rig, &maps.h0.data)), || {
        [bytemuck::cast_slice::<f32, u8>(&rig), h0].map(|b| {
            gpu::count_buffer_upload();
            compute_chain::storage_buffer(device, what, b.len() as u64, Some(b))
        })
    });
    let hb = crate::runtime::frame_pool::storage_buffer(device, what, sizes[3]);
    let groups = compute_chain::groups_8x8(width, height);
    let pack = Stage { entry: "into_skin_maps", groups, args: [stride, 0, 0, 0] };
    let bound = [uvc, &rig_buf, &h0_buf, &hb, skin_maps];
    let uniform = bytemuck::bytes_of(&params);
    compute_chain::record(device, enc, what, SOURCE, uniform, &bound, &[Stage::new("main", groups), pack]);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> Vec<String> {
        ["neutral", "joy", "anger"].map(String::from).to_vec()
    }

    /// Full anger with the global state: g = 1.27 (thesis §7.7); half fear: g = 1 − 0.5·0.19.
    #[test]
    fn the_global_state_scales_as_the_thesis_says() {
        let globals = vec![("anger".to_string(), 1.27), ("fear".to_string(), 0.81)];
        let j = serde_json::json!({"anger": 1.0, "global": {"anger": 1.0}});
        let p = RigPose::from_json(&j, &names(), &globals).unwrap();
        assert_eq!(p.weights, vec![0.0, 0.0, 1.0]);
        assert!((p.global_scale - 1.27).abs() < 1e-6);
        let j = serde_json::json!({"neutral": 1.0, "global": {"fear": 0.5}});
        assert!((RigPose::from_json(&j, &names(), &globals).unwrap().global_scale - 0.905).abs() < 1e-6);
    }

    #[test]
    fn bad_poses_are_refused_naming_the_flag() {
        let globals = vec![("anger".to_string(), 1.27)];
        for j in [
            serde_json::json!({"neutral": 0.5}),
            serde_json::json!({"smile": 1.0}),
            serde_json::json!({"neutral": 1.0, "global": {"anger": 1.5}}),
            serde_json::json!({"neutral": 1.0, "global": {"joy": 0.5}}),
            serde_json::json!([1.0]),
        ] {
            let e = RigPose::from_json(&j, &names(), &globals).unwrap_err();
            assert_eq!(e.param, RIG_WEIGHTS_PARAM, "{j}");
        }
    }
}
