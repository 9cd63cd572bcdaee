//! The one place the runtime chooses between a GPU pass and its CPU twin (as pbrt-v4 switches CPU/GPU once).
//!
//! A caller says where the work runs with a [`Backend`] (`Option<&Gpu>` converts: `None` = the CPU twins); a pass
//! offers both implementations and [`Backend::run`] runs the one the backend names. A pass whose resources live
//! across frames is set up once with [`Backend::prepare`] and run per frame through [`Prepared::run`]. Nothing else
//! in the runtime matches on a backend or on an optional device.

use super::device::Gpu;
use super::RuntimeError;

/// Where the runtime's passes run: on a device, or as their CPU twins (rayon, no adapter).
#[derive(Clone, Copy)]
pub enum Backend<'g> {
    Gpu(&'g Gpu),
    Cpu,
}

impl<'g> From<Option<&'g Gpu>> for Backend<'g> {
    /// `None` = the CPU twins.
    fn from(gpu: Option<&'g Gpu>) -> Self {
        match gpu {
            Some(g) => Backend::Gpu(g),
            None => Backend::Cpu,
        }
    }
}

impl<'g> Backend<'g> {
    /// The CPU twins.
    pub fn cpu() -> Self {
        Backend::Cpu
    }

    /// True on a device (for estimates that differ between the two).
    pub fn is_gpu(self) -> bool {
        matches!(self, Backend::Gpu(_))
    }

    /// Runs `on_gpu` on the device, or `on_cpu`, the pass's CPU twin.
    pub fn run<T>(
        self,
        on_gpu: impl FnOnce(&'g Gpu) -> Result<T, RuntimeError>,
        on_cpu: impl FnOnce() -> Result<T, RuntimeError>,
    ) -> Result<T, RuntimeError> {
        match self {
            Backend::Gpu(g) => on_gpu(g),
            Backend::Cpu => on_cpu(),
        }
    }

    /// Sets a pass up once on this backend: `on_gpu` creates its device resources, `on_cpu` its CPU twin's state.
    pub fn prepare<G, C>(
        self,
        on_gpu: impl FnOnce(&'g Gpu) -> Result<G, RuntimeError>,
        on_cpu: impl FnOnce() -> Result<C, RuntimeError>,
    ) -> Result<Prepared<'g, G, C>, RuntimeError> {
        Ok(match self {
            Backend::Gpu(g) => Prepared::Gpu(g, on_gpu(g)?),
            Backend::Cpu => Prepared::Cpu(on_cpu()?),
        })
    }
}

/// A pass set up on one backend by [`Backend::prepare`]: its device and GPU resources, or its CPU twin's state.
pub enum Prepared<'g, G, C> {
    Gpu(&'g Gpu, G),
    Cpu(C),
}

impl<G, C> Prepared<'_, G, C> {
    /// Runs one step on the backend the pass was set up on.
    pub fn run<T>(&mut self, on_gpu: impl FnOnce(&Gpu, &mut G) -> T, on_cpu: impl FnOnce(&mut C) -> T) -> T {
        match self {
            Prepared::Gpu(g, p) => on_gpu(g, p),
            Prepared::Cpu(c) => on_cpu(c),
        }
    }
}
