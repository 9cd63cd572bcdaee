//! Typed image buffers shared by every baker: row-major, **top row first**, channels interleaved.
//!
//! Bakers return these; only `crate::io` turns them into file bytes.

/// A `width × height` image with `channels` interleaved samples per texel, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Image<T> {
    pub width: u32,
    pub height: u32,
    pub channels: u32,
    pub data: Vec<T>,
}

impl<T: Copy + Default> Image<T> {
    /// A zero-filled image. Callers validate sizes before allocating (see `crate::error::check_size`).
    pub fn new(width: u32, height: u32, channels: u32) -> Self {
        let n = width as usize * height as usize * channels as usize;
        Self { width, height, channels, data: vec![T::default(); n] }
    }

    /// Wraps existing data; panics if the length does not match (a programming error, not user input).
    pub fn from_vec(width: u32, height: u32, channels: u32, data: Vec<T>) -> Self {
        assert_eq!(data.len(), width as usize * height as usize * channels as usize, "image data length");
        Self { width, height, channels, data }
    }

    #[inline]
    pub fn index(&self, x: u32, y: u32, c: u32) -> usize {
        ((y as usize * self.width as usize + x as usize) * self.channels as usize) + c as usize
    }

    #[inline]
    pub fn get(&self, x: u32, y: u32, c: u32) -> T {
        self.data[self.index(x, y, c)]
    }

    #[inline]
    pub fn set(&mut self, x: u32, y: u32, c: u32, v: T) {
        let i = self.index(x, y, c);
        self.data[i] = v;
    }

    /// One row (all channels), top row is `y = 0`.
    pub fn row(&self, y: u32) -> &[T] {
        let w = self.width as usize * self.channels as usize;
        &self.data[y as usize * w..(y as usize + 1) * w]
    }

    pub fn row_mut(&mut self, y: u32) -> &mut [T] {
        let w = self.width as usize * self.channels as usize;
        &mut self.data[y as usize * w..(y as usize + 1) * w]
    }
}

pub type ImageU8 = Image<u8>;
pub type ImageF32 = Image<f32>;
