//! The melanin × hemoglobin skin-colour lookup table (thesis §7.6, eq. 7.7, Table 7.1, Fig. 7.9).
//!
//! Eq. 7.7 indexes the table by the cube roots u = ∛Cm, v = ∛Chd. The default ("normalised") form spans Table
//! 7.1's ranges: u = ∛(Cm / 0.5), v = ∛(Chd / 0.32); the literal form (`literal-cbrt`) uses u = ∛Cm, v = ∛Chd over
//! [0, 1]. Texel convention (node-inclusive): column i of a W-wide table holds t = i / (W − 1), Cm = Cm,max · t³;
//! row j of an H-high table holds Chd = Chd,max · (j / (H − 1))³. Melanin varies along u (columns, left → right),
//! hemoglobin along v (rows); rows are stored top row first and **row 0 (texcoord v = 0) is Chd = 0**.
//! A shader sampling with bilinear filtering and normalised texture coordinates uses
//!
//!   texcoord.x = (∛(Cm / Cm,max) · (W − 1) + 0.5) / W,   texcoord.y = (∛(Chd / Chd,max) · (H − 1) + 0.5) / H
//!
//! so that t = 0 and t = 1 land on the centres of the first and last texels.

use super::two_layer::{SkinColorError, TwoLayerSkinModel};
use crate::error::{check_range, InvalidInput};
use crate::image_buf::Image;
use crate::spectral::skin_layers::{DERMAL_HEMOGLOBIN_FRACTION_MAX, MELANIN_FRACTION_MAX};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Smallest and largest LUT edge (texels). Two texels are needed for t = i/(n − 1); the upper limit keeps a bake
/// (≈ 401 multipole evaluations per texel) within minutes and is checked before anything is allocated.
pub const MIN_EDGE: u32 = 2;
pub const MAX_EDGE: u32 = 2048;

/// How concentrations map to the [0, 1] table axes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IndexForm {
    /// u = ∛(Cm / 0.5), v = ∛(Chd / 0.32): Table 7.1's ranges fill the table (default).
    #[default]
    NormalizedCbrt,
    /// u = ∛Cm, v = ∛Chd as printed in eq. 7.7: the table spans [0, 1] for both fractions.
    LiteralCbrt,
}

impl IndexForm {
    /// Cm at t = 1.
    pub fn melanin_max(self) -> f64 {
        match self {
            Self::NormalizedCbrt => MELANIN_FRACTION_MAX,
            Self::LiteralCbrt => 1.0,
        }
    }
    /// Chd at t = 1.
    pub fn hemoglobin_max(self) -> f64 {
        match self {
            Self::NormalizedCbrt => DERMAL_HEMOGLOBIN_FRACTION_MAX,
            Self::LiteralCbrt => 1.0,
        }
    }
}

/// Size and index mapping of the table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LutLayout {
    pub width: u32,
    pub height: u32,
    pub index_form: IndexForm,
}

impl LutLayout {
    /// Validates the size (before anything is allocated).
    pub fn new(width: u32, height: u32, index_form: IndexForm) -> Result<Self, InvalidInput> {
        check_range("width", width, MIN_EDGE, MAX_EDGE, "texels")?;
        check_range("height", height, MIN_EDGE, MAX_EDGE, "texels")?;
        Ok(Self { width, height, index_form })
    }

    /// Cm of column `i`: Cm,max · (i / (W − 1))³ (inverse of eq. 7.7).
    pub fn melanin_at_column(&self, i: u32) -> f64 {
        let t = i as f64 / (self.width - 1) as f64;
        self.index_form.melanin_max() * t * t * t
    }

    /// Chd of row `j` (row 0 = top = Chd 0): Chd,max · (j / (H − 1))³.
    pub fn hemoglobin_at_row(&self, j: u32) -> f64 {
        let t = j as f64 / (self.height - 1) as f64;
        self.index_form.hemoglobin_max() * t * t * t
    }

    /// Eq. 7.7: the axis coordinates (u, v) ∈ [0, 1]² of (Cm, Chd) (before the texel-centre mapping).
    pub fn uv(&self, cm: f64, chd: f64) -> (f64, f64) {
        // eq. 7.7 (normalised by the axis maxima in the default form)
        ((cm / self.index_form.melanin_max()).cbrt(), (chd / self.index_form.hemoglobin_max()).cbrt())
    }

    /// Normalised texture coordinates of (Cm, Chd) for bilinear sampling (texel centres at the nodes).
    pub fn texcoord(&self, cm: f64, chd: f64) -> (f64, f64) {
        let (u, v) = self.uv(cm, chd);
        let (w, h) = (self.width as f64, self.height as f64);
        ((u * (w - 1.0) + 0.5) / w, (v * (h - 1.0) + 0.5) / h)
    }
}

/// How the table evaluates the epidermis' multipole totals.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LutEvaluation {
    /// Exact-series totals tabulated per wavelength against √σa and interpolated (see
    /// `two_layer::EpidermisTable`; differs from `direct` by < 1e−7 in linear RGB). Default.
    #[default]
    Tabulated,
    /// `Slab::totals(Series::Exact)` for every texel and wavelength (about 10–20× slower).
    Direct,
}

/// Accumulator bytes of one parallel task (3 f64 per texel) that [`rows_per_task`] aims for: about three quarters of
/// the 1 MiB L2 cache of the project's AMD EPYC, so a task's accumulators stay in L2 while every band's
/// [`two_layer::EpidermisTable`](super::two_layer::EpidermisTable) (32 KiB) is streamed from L3 once per task.
const TASK_ACCUMULATOR_BYTES: usize = 768 << 10;
/// Fewest rows per task (progress granularity and the per-task set-up).
const MIN_ROWS_PER_TASK: usize = 8;

/// Rows per parallel task of a `width`-wide, `height`-high table on `threads` threads: one task per thread where
/// the accumulators fit `TASK_ACCUMULATOR_BYTES`, fewer rows otherwise (at least `MIN_ROWS_PER_TASK`). Every band
/// table is read once per task, so few tall tasks cut the traffic: 256² at 401 bands, one thread, CPU time 84 → 54
/// ms from 8 to 128 rows per task (measured under load, `examples/bench_skin.rs`). The table's values do not depend
/// on it (each texel sums its bands in the same order whichever task computes it).
pub fn rows_per_task(width: u32, height: u32, threads: usize) -> usize {
    let per_thread = (height as usize).div_ceil(threads.max(1));
    let fit = TASK_ACCUMULATOR_BYTES / (3 * std::mem::size_of::<f64>() * width.max(1) as usize);
    per_thread.min(fit).max(MIN_ROWS_PER_TASK)
}

/// Bakes the table: W × H linear sRGB (3 channels, f32), top row first, deterministic for any thread count
/// (every texel sums its wavelengths in the same order whichever task computes it).
pub fn bake_lut(
    model: &TwoLayerSkinModel,
    layout: &LutLayout,
    evaluation: LutEvaluation,
) -> Result<Image<f32>, SkinColorError> {
    bake_lut_with_progress(model, layout, evaluation, &|_, _| {})
}

/// [`bake_lut`], calling `progress(rows_done, rows)` as rows complete (from the worker threads, in completion
/// order; the table itself does not depend on it), so a caller can show progress on large tables.
pub fn bake_lut_with_progress(
    model: &TwoLayerSkinModel,
    layout: &LutLayout,
    evaluation: LutEvaluation,
    progress: &(dyn Fn(u32, u32) + Sync),
) -> Result<Image<f32>, SkinColorError> {
    let (cm_max, chd_max) = (layout.index_form.melanin_max(), layout.index_form.hemoglobin_max());
    model.check_validity(cm_max, chd_max)?;
    let tables = match evaluation {
        LutEvaluation::Tabulated => model.epidermis_tables(cm_max, chd_max),
        LutEvaluation::Direct => vec![None; model.wavelengths_nm().len()],
    };
    let melanin: Vec<f64> = (0..layout.width).map(|i| layout.melanin_at_column(i)).collect();
    let hemoglobin: Vec<f64> = (0..layout.height).map(|j| layout.hemoglobin_at_row(j)).collect();
    let row_len = 3 * layout.width as usize;
    let mut img = Image::new(layout.width, layout.height, 3);
    let rows_done = std::sync::atomic::AtomicU32::new(0);
    let rows = rows_per_task(layout.width, layout.height, rayon::current_num_threads());
    img.data.par_chunks_mut(row_len * rows).zip(hemoglobin.par_chunks(rows)).for_each(|(out, chd)| {
        model.linear_rgb_grid(&melanin, chd, &tables, out);
        let done = rows_done.fetch_add(chd.len() as u32, std::sync::atomic::Ordering::Relaxed) + chd.len() as u32;
        progress(done, layout.height);
    });
    Ok(img)
}

/// Wall time of [`bake_lut`] (the budget check before any work): per texel and wavelength band 30 ns
/// tabulated, 250 ns direct, on one thread, divided by `threads`, plus 1 s of model set-up (the epidermis tables).
/// Measured with the release build on the project's 2-core machine (256² at 401 bands on one thread: 0.6–0.7 s
/// tabulated before the vectorised row loop, 0.07 s with it; 4.5–5.9 s direct); the estimate rounds up.
pub fn time_estimate_seconds(layout: &LutLayout, evaluation: LutEvaluation, bands: usize, threads: usize) -> f64 {
    let per_eval = match evaluation {
        LutEvaluation::Tabulated => 30e-9,
        LutEvaluation::Direct => 250e-9,
    };
    1.0 + per_eval * layout.width as f64 * layout.height as f64 * bands as f64 / threads.max(1) as f64
}

/// Peak memory of a table bake with its files, in bytes: the f32 table, its f16/EXR/KTX2/PNG encodings and the
/// per-task accumulators, about 64 bytes per texel, plus 64 MiB of model and spectra.
pub fn memory_estimate_bytes(layout: &LutLayout) -> u64 {
    64 * layout.width as u64 * layout.height as u64 + (64 << 20)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Progress reaches every row exactly once in total, and reporting it does not change the table.
    #[test]
    fn progress_counts_every_row_and_leaves_the_table_unchanged() {
        let p = crate::skin_color::SkinColorParams { width: 6, height: 40, ..Default::default() };
        let (model, layout) = (p.model().unwrap(), p.layout().unwrap());
        let max = std::sync::atomic::AtomicU32::new(0);
        let calls = std::sync::atomic::AtomicU32::new(0);
        let with = bake_lut_with_progress(&model, &layout, p.lut_evaluation, &|done, rows| {
            assert_eq!(rows, 40);
            max.fetch_max(done, std::sync::atomic::Ordering::Relaxed);
            calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        })
        .unwrap();
        assert_eq!(max.into_inner(), 40);
        let tasks = 40usize.div_ceil(rows_per_task(6, 40, rayon::current_num_threads()));
        assert!(calls.into_inner() as usize >= tasks);
        assert_eq!(with, bake_lut(&model, &layout, p.lut_evaluation).unwrap());
    }

    #[test]
    fn tasks_fit_the_accumulator_budget_and_split_the_rows_between_threads() {
        assert_eq!(rows_per_task(256, 256, 2), 128);
        assert_eq!(rows_per_task(256, 256, 64), MIN_ROWS_PER_TASK);
        // 2048 wide: 48 KiB of accumulators per row, 16 rows in 768 KiB.
        assert_eq!(rows_per_task(2048, 2048, 1), 16);
        assert!(rows_per_task(2, 2, 0) >= 2);
    }
}
