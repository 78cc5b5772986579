//! The image being rendered: linear RGB floats, as both engines fill it. Its files (PNG, PPM,
//! PFM, EXR) are the output layer's (`output::image_file`).

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Linear RGB pixels, row-major from the top-left.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` colours.
    pub pixels: Vec<Vec3>,
}

/// How linear values become 8-bit pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ToneMap {
    /// The lab's look: clamp to [0, 1], no gamma.
    Clamp,
    /// The lab's key 'h': 1 − exp(−3x).
    Exp,
}

impl Film {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Film {
        Film {
            width,
            height,
            pixels: vec![Vec3::ZERO; width as usize * height as usize],
        }
    }

    /// How many pixels have a channel that is not finite.
    pub fn non_finite_pixels(&self) -> usize {
        self.pixels.iter().filter(|c| !c.is_finite()).count()
    }
}
