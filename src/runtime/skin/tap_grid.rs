//! TAP 2009's stimulus grid (Jimenez, Sundstedt & Gutierrez, ACM TAP 6(4), §6 and Figs. 4, 6–9): the head rendered
//! with the four shaders of the experiment — TS (texture-space diffusion, the reference), SS Full, SS Jittered and
//! No SSS — under a single light at the four azimuths ϕ = 0°, 60°, 110°, 150° (elevation θ = 45°) from the three
//! camera distances zoom, near and far (28, 50 and 132 units for a 27-unit head, scaled to the mesh's head
//! height); the RMSE of every frame against TS under the same condition; and the α/β sweep of TAP Fig. 4 (top:
//! β = 800, α = 0, 5.5, 11; bottom: α = 11, β = 0, 400, 800; near, ϕ = 0°) with its RMSE against TS.
//!
//! RMSE is over the R, G and B channels of the whole sRGB-encoded frame in 0..=1 (the background, equal in both,
//! counts as zeros), as `report` prints and the README quotes. Pure orchestration over
//! [`crate::runtime::skin::frame::render_with`]; the caller writes the files ([`TapGrid::files`]).

use crate::error::InvalidInput;
use crate::image_buf::Image;
use crate::mesh::framing::{TapDistance, TAP_LIGHT_AZIMUTHS_DEG, TAP_LIGHT_ELEVATION_DEG};
use crate::mesh::Mesh;
use crate::runtime::backend::Backend;
use crate::runtime::skin::frame::render_with;
use crate::runtime::skin::lighting::{DemoAssets, SceneLights};
use crate::runtime::skin::passes::SkinPasses;
use crate::runtime::skin::settings::{SkinRenderSettings, SkinShader, StretchPreset, TsSettings};
use crate::runtime::sss::gaussian::GaussianSssParams;
use crate::runtime::RuntimeError;

/// TAP's shaders, in the order of its Table II and Fig. 8 (TS first: the reference).
pub const GRID_SHADERS: [&str; 4] = ["ts", "ss-full", "ss-jittered", "no-sss"];
/// The shader the grid adds on request ([`TapGridSettings::separable`]): separable SSS (thesis ch. 6), which came
/// after TAP 2009 and is not one of its stimuli.
pub const SEPARABLE_SHADER: &str = "separable";

/// The name TAP (and the thesis, for separable) print for a grid shader: "TS", "SS Full", "SS Jittered", "No SSS",
/// "Separable".
pub fn display_name(shader: &str) -> &'static str {
    match shader {
        "ts" => "TS",
        "ss-full" => "SS Full",
        "ss-jittered" => "SS Jittered",
        "no-sss" => "No SSS",
        _ => "Separable",
    }
}
/// TAP Fig. 4's sweep: (α, β) as printed, for the thesis' 20° field of view (scaled to the camera's as
/// [`StretchPreset::apply`] does).
pub const FIG4_SWEEP: [(f32, f32); 6] =
    [(0.0, 800.0), (5.5, 800.0), (11.0, 800.0), (11.0, 0.0), (11.0, 400.0), (11.0, 800.0)];
/// Scale of the difference images: |Δ| × 8, so a difference of 1/8 is white.
pub const DIFFERENCE_SCALE: f32 = 8.0;

/// What the grid renders.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TapGridSettings {
    pub width: u32,
    pub height: u32,
    /// The mesh's head height (crown to chin), m: the camera distances keep TAP's ratios to it.
    pub head_height_m: f32,
    /// SS Full's stretch preset (the grid's "SS Full").
    pub stretch: StretchPreset,
    /// TS's irradiance map edge, texels.
    pub ts_map_size: u32,
    pub melanin: f32,
    /// Also render [`SEPARABLE_SHADER`] under every condition (after TAP's four), so the frames, differences and
    /// RMSE table compare all five of `run skin`'s shaders against TS.
    pub separable: bool,
}

impl TapGridSettings {
    /// The shaders rendered under every condition: [`GRID_SHADERS`] (TS first), then [`SEPARABLE_SHADER`] when asked.
    pub fn shaders(&self) -> Vec<&'static str> {
        let mut v = GRID_SHADERS.to_vec();
        if self.separable {
            v.push(SEPARABLE_SHADER);
        }
        v
    }

    /// The frame settings of `shader` (one of [`TapGridSettings::shaders`]) at `distance`.
    pub fn frame(&self, shader: &str, distance: TapDistance) -> SkinRenderSettings {
        let shader = match shader {
            "ts" => SkinShader::Ts(TsSettings { map_size: self.ts_map_size, ..Default::default() }),
            "ss-full" => SkinShader::SsFull,
            "ss-jittered" => SkinShader::SsJittered,
            SEPARABLE_SHADER => SkinShader::Separable,
            _ => SkinShader::None,
        };
        SkinRenderSettings {
            shader,
            heads: 1,
            distance_m: distance.camera_distance_m(self.head_height_m),
            width: self.width,
            height: self.height,
            melanin: self.melanin,
            stretch: self.stretch,
        }
    }

    /// Every frame's settings validated before any work (sizes, distances, map size).
    pub fn validate(&self) -> Result<(), InvalidInput> {
        for d in TapDistance::ALL {
            for sh in self.shaders() {
                self.frame(sh, d).validate()?;
            }
        }
        TsSettings { map_size: self.ts_map_size, ..Default::default() }.validate()
    }

    /// Every frame of the grid and the sweep, for budget checks: 48 (60 with separable) + the 6 of the sweep.
    pub fn frames(&self) -> Vec<SkinRenderSettings> {
        let mut v = Vec::new();
        for d in TapDistance::ALL {
            for sh in self.shaders() {
                v.extend(std::iter::repeat_n(self.frame(sh, d), TAP_LIGHT_AZIMUTHS_DEG.len()));
            }
        }
        v.extend(std::iter::repeat_n(self.frame("ss-full", TapDistance::Near), FIG4_SWEEP.len()));
        v
    }
}

/// One frame of the grid.
#[derive(Clone, Debug)]
pub struct GridFrame {
    pub shader: &'static str,
    pub distance: TapDistance,
    pub azimuth_deg: f32,
    pub image: Image<u8>,
    /// RMSE against TS under the same condition (0 for TS itself).
    pub rmse: f64,
}

/// One frame of the Fig. 4 sweep.
#[derive(Clone, Debug)]
pub struct SweepFrame {
    pub alpha: f32,
    pub beta: f32,
    pub image: Image<u8>,
    pub rmse: f64,
}

/// The grid, the sweep and their RMSE.
#[derive(Clone, Debug)]
pub struct TapGrid {
    pub settings: TapGridSettings,
    pub frames: Vec<GridFrame>,
    pub sweep: Vec<SweepFrame>,
}

/// RMSE of the RGB channels of two equal-sized 8-bit frames, in 0..=1.
pub fn rmse_rgb(a: &Image<u8>, b: &Image<u8>) -> f64 {
    assert_eq!((a.width, a.height, a.channels), (b.width, b.height, b.channels));
    let ch = a.channels as usize;
    let mut sum = 0.0f64;
    for (p, q) in a.data.chunks_exact(ch).zip(b.data.chunks_exact(ch)) {
        for c in 0..3 {
            let d = (p[c] as f64 - q[c] as f64) / 255.0;
            sum += d * d;
        }
    }
    (sum / (3.0 * (a.width * a.height) as f64)).sqrt()
}

/// Renders the grid and the sweep of `mesh` (metres) with `passes` (surface maps, MSAA, bloom) and `assets`;
/// `progress` is called after each frame with the number done.
pub fn render_grid<'g>(
    gpu: impl Into<Backend<'g>>,
    mesh: &Mesh,
    s: &TapGridSettings,
    passes: &SkinPasses,
    assets: &DemoAssets,
    progress: &dyn Fn(usize),
) -> Result<TapGrid, RuntimeError> {
    let gpu: Backend = gpu.into();
    s.validate()?;
    let mut frames = Vec::new();
    let mut done = 0;
    let mut render = |fs: &SkinRenderSettings, az: f32, a: &DemoAssets| -> Result<Image<u8>, RuntimeError> {
        let mut a = a.clone();
        a.lights = SceneLights::single(az, TAP_LIGHT_ELEVATION_DEG, &fs.camera())?;
        let img = render_with(gpu, mesh, fs, passes, &a)?;
        done += 1;
        progress(done);
        Ok(img)
    };
    for d in TapDistance::ALL {
        for az in TAP_LIGHT_AZIMUTHS_DEG {
            let mut ts: Option<Image<u8>> = None;
            for sh in s.shaders() {
                let img = render(&s.frame(sh, d), az, assets)?;
                let rmse = ts.as_ref().map_or(0.0, |t| rmse_rgb(&img, t));
                if ts.is_none() {
                    ts = Some(img.clone());
                }
                frames.push(GridFrame { shader: sh, distance: d, azimuth_deg: az, image: img, rmse });
            }
        }
    }
    let ts_near = frames
        .iter()
        .find(|f| f.shader == "ts" && f.distance == TapDistance::Near && f.azimuth_deg == 0.0)
        .map(|f| f.image.clone())
        .expect("the grid has TS at near, 0°");
    let mut sweep = Vec::new();
    for (alpha, beta) in FIG4_SWEEP {
        // StretchPreset::Thesis scales the given α from TAP's 20° to the camera's field of view.
        let mut a = assets.clone();
        a.gaussian_params = GaussianSssParams { alpha, beta, gamma: f32::MAX, ..assets.gaussian_params };
        let mut fs = SkinRenderSettings { stretch: StretchPreset::Thesis, ..s.frame("ss-full", TapDistance::Near) };
        if alpha == 0.0 {
            // α = 0 shrinks every Gaussian to nothing (eq. 2–3): the diffuse light unblurred, which the pass
            // refuses as a parameter; the no-SSS frame is that image.
            fs.shader = SkinShader::None;
        }
        let image = render(&fs, 0.0, &a)?;
        let rmse = rmse_rgb(&image, &ts_near);
        sweep.push(SweepFrame { alpha, beta, image, rmse });
    }
    Ok(TapGrid { settings: *s, frames, sweep })
}

fn az_name(az: f32) -> String {
    format!("az{:03}", az as i32)
}

impl TapGrid {
    /// The frame of `shader` at `distance` and azimuth `az`.
    pub fn frame(&self, shader: &str, distance: TapDistance, az: f32) -> Option<&GridFrame> {
        self.frames.iter().find(|f| f.shader == shader && f.distance == distance && f.azimuth_deg == az)
    }

    /// The RMSE table as CSV: `shader,distance,azimuth_deg,elevation_deg,rmse_vs_ts`, then the sweep's rows
    /// (`ss-full alpha=A beta=B,near,0,45,RMSE`).
    pub fn rmse_csv(&self) -> String {
        let mut out = String::from("shader,distance,azimuth_deg,elevation_deg,rmse_vs_ts\n");
        for f in self.frames.iter().filter(|f| f.shader != "ts") {
            out += &format!(
                "{},{},{},{},{:.6}\n",
                f.shader,
                f.distance.name(),
                f.azimuth_deg,
                TAP_LIGHT_ELEVATION_DEG,
                f.rmse
            );
        }
        for w in &self.sweep {
            out += &format!(
                "ss-full alpha={} beta={},near,0,{},{:.6}\n",
                w.alpha, w.beta, TAP_LIGHT_ELEVATION_DEG, w.rmse
            );
        }
        out
    }

    /// Mean RMSE against TS of `shader` over the 12 conditions (NaN when the grid has no such shader).
    pub fn mean_rmse(&self, shader: &str) -> f64 {
        let v: Vec<f64> = self.frames.iter().filter(|f| f.shader == shader).map(|f| f.rmse).collect();
        v.iter().sum::<f64>() / v.len() as f64
    }

    /// The RMSE table as JSON (per condition, per shader mean, the sweep) with the frame size and camera.
    pub fn rmse_json(&self, describe: serde_json::Value) -> serde_json::Value {
        let s = &self.settings;
        serde_json::json!({
            "what": "RMSE against TS (RGB, sRGB-encoded 0..1, whole frame), TAP 2009 stimulus grid",
            "frame": [s.width, s.height],
            "head_height_m": s.head_height_m,
            "elevation_deg": TAP_LIGHT_ELEVATION_DEG,
            "distances_m": TapDistance::ALL.iter().map(|d| (d.name(), d.camera_distance_m(s.head_height_m)))
                .collect::<std::collections::BTreeMap<_, _>>(),
            "ts_map_size": s.ts_map_size,
            "ss_full_stretch": format!("{:?}", s.stretch).to_lowercase(),
            "mean_rmse": s.shaders()[1..].iter().map(|sh| (*sh, self.mean_rmse(sh)))
                .collect::<std::collections::BTreeMap<_, _>>(),
            "conditions": self.frames.iter().filter(|f| f.shader != "ts").map(|f| serde_json::json!({
                "shader": f.shader, "distance": f.distance.name(), "azimuth_deg": f.azimuth_deg, "rmse": f.rmse,
            })).collect::<Vec<_>>(),
            "fig4_sweep": self.sweep.iter().map(|w| serde_json::json!({
                "alpha": w.alpha, "beta": w.beta, "rmse": w.rmse,
            })).collect::<Vec<_>>(),
            "run": describe,
        })
    }

    /// Every file of the folder: `frames/SHADER_DISTANCE_azAAA.png` (48), `differences/…png` against TS (36, |Δ|×8
    /// with a legend), `fig4/{alpha,beta}_sweep_alpha_A_beta_B.png` (6), `rmse.csv`, `rmse.json`, `contact_sheet.png` (rows: shaders
    /// and differences; columns: distance × azimuth) and `fig4_sweep.png` (TAP Fig. 4's layout).
    pub fn files(&self, describe: serde_json::Value) -> Result<Vec<(String, Vec<u8>)>, crate::io::IoError> {
        use crate::io::png::encode_u8_frame;
        use crate::plot::sheet::{contact_sheet, difference_image};
        let mut files = Vec::new();
        let mut diffs = Vec::new();
        for f in &self.frames {
            let stem = format!("{}_{}_{}", f.shader, f.distance.name(), az_name(f.azimuth_deg));
            files.push((format!("frames/{stem}.png"), encode_u8_frame(&f.image)?));
            if f.shader != "ts" {
                let ts = self.frame("ts", f.distance, f.azimuth_deg).expect("TS under every condition");
                let d = difference_image(&f.image, &ts.image, DIFFERENCE_SCALE);
                files.push((format!("differences/{stem}.png"), crate::io::png::encode_u8(&d)?));
                diffs.push((f.shader, f.distance, f.azimuth_deg, d));
            }
        }
        for (k, w) in self.sweep.iter().enumerate() {
            let row = if k < 3 { "alpha_sweep" } else { "beta_sweep" };
            files.push((format!("fig4/{row}_alpha_{}_beta_{}.png", w.alpha, w.beta), encode_u8_frame(&w.image)?));
        }
        files.push(("rmse.csv".into(), self.rmse_csv().into_bytes()));
        let json = serde_json::to_string_pretty(&self.rmse_json(describe)).expect("JSON of numbers and strings");
        files.push(("rmse.json".into(), (json + "\n").into_bytes()));
        // The contact sheet: a row per shader, then a row per difference; a column per (distance, azimuth).
        let conditions: Vec<(TapDistance, f32)> =
            TapDistance::ALL.iter().flat_map(|&d| TAP_LIGHT_AZIMUTHS_DEG.map(|a| (d, a))).collect();
        let columns: Vec<String> = conditions.iter().map(|(d, a)| format!("{} {}°", d.name(), *a as i32)).collect();
        let shaders = self.settings.shaders();
        let mut rows: Vec<String> = shaders.iter().map(|s| s.to_uppercase()).collect();
        let mut cells: Vec<Option<&Image<u8>>> = Vec::new();
        for &sh in &shaders {
            cells.extend(conditions.iter().map(|&(d, a)| self.frame(sh, d, a).map(|f| &f.image)));
        }
        for sh in &shaders[1..] {
            rows.push(format!("{} - TS x{}", sh.to_uppercase(), DIFFERENCE_SCALE));
            cells.extend(
                conditions
                    .iter()
                    .map(|&(d, a)| diffs.iter().find(|(s, dd, aa, _)| s == sh && *dd == d && *aa == a).map(|x| &x.3)),
            );
        }
        let (w, h) = (self.settings.width, self.settings.height);
        let means: Vec<String> =
            shaders[1..].iter().map(|sh| format!("{} {:.4}", display_name(sh), self.mean_rmse(sh))).collect();
        let title =
            format!("TAP 2009 stimulus grid, {w}x{h}, light elevation 45 deg; mean RMSE vs TS: {}", means.join(", "));
        let sheet = contact_sheet(&title, &rows, &columns, &cells, w, h);
        files.push(("contact_sheet.png".into(), crate::io::png::encode_u8(&sheet)?));
        let sweep_rows = vec!["beta = 800".to_string(), "alpha = 11".to_string()];
        let sweep_cols: Vec<String> =
            (0..3).map(|k| format!("a {} / b {}", FIG4_SWEEP[k].0, FIG4_SWEEP[3 + k].1)).collect();
        let cells: Vec<Option<&Image<u8>>> = self.sweep.iter().map(|w| Some(&w.image)).collect();
        let title = format!(
            "TAP Fig. 4: SS Full, near, 0 deg; RMSE vs TS {}",
            self.sweep.iter().map(|w| format!("{:.4}", w.rmse)).collect::<Vec<_>>().join(" ")
        );
        files.push((
            "fig4_sweep.png".into(),
            crate::io::png::encode_u8(&contact_sheet(&title, &sweep_rows, &sweep_cols, &cells, w, h))?,
        ));
        Ok(files)
    }
}
