//! simVision's two image buffers beside a sensor's work image (`simVision.workImgToBuffer1`,
//! `buffer1ToWorkImg`, `swapBuffers`, `addBuffer1ToWorkImg` ...): scripts keep a copy of
//! the camera image there while they filter the work image (a colour for each blob
//! search), and the scanner functions read point colours from buffer 1
//! (`returnRgb`).
//!
//! A buffer holds float RGB like the work image (`3 * width * height` values, bottom
//! row first). One never written, or written at another resolution, reads as black:
//! the plugin leaves such a buffer uninitialised.

use super::{Work, WorkImage, blobs};

/// Which buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Buffer {
    /// Buffer 1.
    One,
    /// Buffer 2.
    Two,
}

/// An arithmetic operation between the work image and buffer 1, each clamped as the
/// plugin clamps it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BufferOp {
    /// `addWorkImgToBuffer1`: buffer 1 += work, at most 1.
    AddWorkToBuffer1,
    /// `subtractWorkImgFromBuffer1`: buffer 1 -= work, at least 0.
    SubtractWorkFromBuffer1,
    /// `addBuffer1ToWorkImg`: work += buffer 1, at most 1.
    AddBuffer1ToWork,
    /// `subtractBuffer1FromWorkImg`: work -= buffer 1, at least 0.
    SubtractBuffer1FromWork,
    /// `multiplyWorkImgWithBuffer1`: work *= buffer 1, at most 1.
    MultiplyWorkByBuffer1,
}

impl WorkImage<'_> {
    /// Buffer `b`, black at the work image's size if it was never written or was
    /// written at another resolution.
    fn buffer(&mut self, b: Buffer) -> &mut Vec<f32> {
        let n = 3 * self.width * self.height;
        let buffer = &mut self.buffers[b as usize];
        if buffer.len() != n {
            buffer.clear();
            buffer.resize(n, 0.0);
        }
        buffer
    }

    /// `simVision.selectiveColorOnWorkImg` with `removedPartToBuffer1`
    /// ([`WorkImage::selective_color`] otherwise): the pixels removed also go to buffer 1,
    /// and the others are black there.
    pub fn selective_color_to_buffer1(&mut self, color: [f32; 3], tolerance: [f32; 3], rgb: bool, keep: bool) {
        self.buffer(Buffer::One);
        let buffer1 = Some(self.buffers[Buffer::One as usize].as_mut_slice());
        blobs::selective_color(self.work.floats_mut(), color, tolerance, rgb, keep, buffer1);
    }

    /// `simVision.workImgToBuffer1` / `workImgToBuffer2`: a copy of the work image.
    pub fn to_buffer(&mut self, b: Buffer) {
        let floats = self.work.to_floats();
        *self.buffer(b) = floats;
    }

    /// `simVision.buffer1ToWorkImg` / `buffer2ToWorkImg`: the buffer becomes the work
    /// image.
    pub fn from_buffer(&mut self, b: Buffer) {
        let copy = self.buffer(b).clone();
        *self.work = Work::Float(copy);
    }

    /// `simVision.swapBuffers`: buffer 1 and buffer 2 trade places.
    pub fn swap_buffers(&mut self) {
        self.buffer(Buffer::One);
        self.buffer(Buffer::Two);
        self.buffers.swap(0, 1);
    }

    /// `simVision.swapWorkImgWithBuffer1`: the work image and buffer 1 trade places.
    pub fn swap_with_buffer1(&mut self) {
        let floats = self.work.to_floats();
        let old = std::mem::replace(self.buffer(Buffer::One), floats);
        *self.work = Work::Float(old);
    }

    /// One of the [`BufferOp`]s between the work image and buffer 1, value by value.
    pub fn combine_with_buffer1(&mut self, op: BufferOp) {
        let work = self.work.to_floats();
        let buffer1 = std::mem::take(self.buffer(Buffer::One));
        let (into_buffer, result): (bool, Vec<f32>) = match op {
            BufferOp::AddWorkToBuffer1 => (true, zip(&buffer1, &work, |b, w| (b + w).min(1.0))),
            BufferOp::SubtractWorkFromBuffer1 => (true, zip(&buffer1, &work, |b, w| (b - w).max(0.0))),
            BufferOp::AddBuffer1ToWork => (false, zip(&work, &buffer1, |w, b| (w + b).min(1.0))),
            BufferOp::SubtractBuffer1FromWork => (false, zip(&work, &buffer1, |w, b| (w - b).max(0.0))),
            BufferOp::MultiplyWorkByBuffer1 => (false, zip(&work, &buffer1, |w, b| (w * b).min(1.0))),
        };
        if into_buffer {
            self.buffers[Buffer::One as usize] = result;
        } else {
            self.buffers[Buffer::One as usize] = buffer1;
            *self.work = Work::Float(result);
        }
    }
}

/// `f(a[i], b[i])` for every value.
fn zip(a: &[f32], b: &[f32], f: impl Fn(f32, f32) -> f32) -> Vec<f32> {
    a.iter().zip(b).map(|(&x, &y)| f(x, y)).collect()
}
