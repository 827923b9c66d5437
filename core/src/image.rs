//! In-memory images: a width, a height and a row-major `Vec` of pixels, with bilinear
//! sampling under the project's pixel-centre convention (pixel `(i, j)` is at integer
//! coordinates; see [`crate::conventions`]).

use crate::error::{CoreError, Result};

/// Linear RGB, one `f32` per channel.
pub type Rgb = [f32; 3];
/// Premultiplied linear RGBA.
pub type Rgba = [f32; 4];
/// A displacement `(dx, dy)` in pixels.
pub type Flow = [f32; 2];

/// A linear RGB image.
pub type RgbImage = Image<Rgb>;
/// A one-channel image (luminance, alpha, masks).
pub type GrayImage = Image<f32>;
/// A flow field (see [`crate::conventions`] for its direction).
pub type FlowImage = Image<Flow>;

/// What a pixel type must offer for sampling and blending: a zero and a weighted sum.
pub trait Pixel: Copy + Send + Sync + 'static {
    /// Number of `f32` channels.
    const CHANNELS: usize;
    /// All channels zero.
    fn zero() -> Self;
    /// `self + other * weight`, channel by channel.
    fn add_scaled(self, other: Self, weight: f32) -> Self;
    /// The channels as a slice.
    fn channels(&self) -> &[f32];
}

impl Pixel for f32 {
    const CHANNELS: usize = 1;
    fn zero() -> Self {
        0.0
    }
    fn add_scaled(self, other: Self, weight: f32) -> Self {
        self + other * weight
    }
    fn channels(&self) -> &[f32] {
        std::slice::from_ref(self)
    }
}

impl<const N: usize> Pixel for [f32; N] {
    const CHANNELS: usize = N;
    fn zero() -> Self {
        [0.0; N]
    }
    fn add_scaled(self, other: Self, weight: f32) -> Self {
        let mut out = self;
        for (o, b) in out.iter_mut().zip(other) {
            *o += b * weight;
        }
        out
    }
    fn channels(&self) -> &[f32] {
        self
    }
}

/// What [`Image::sample_bilinear`] does with the part of the 2x2 footprint that falls
/// outside the image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Border {
    /// Repeat the nearest edge pixel.
    Clamp,
    /// Treat outside pixels as zero (transparent black for premultiplied images).
    Zero,
}

/// A row-major image of `P` pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct Image<P> {
    width: usize,
    height: usize,
    pixels: Vec<P>,
}

impl<P: Copy> Image<P> {
    /// An image filled with `value`.
    pub fn new(width: usize, height: usize, value: P) -> Self {
        Self {
            width,
            height,
            pixels: vec![value; width * height],
        }
    }

    /// Wraps `pixels` (row-major, `width * height` of them).
    pub fn from_vec(width: usize, height: usize, pixels: Vec<P>) -> Result<Self> {
        if pixels.len() != width * height {
            return Err(CoreError::invalid(
                "pixels",
                format!(
                    "{} pixels for a {width}x{height} image (needs {})",
                    pixels.len(),
                    width * height
                ),
            ));
        }
        Ok(Self {
            width,
            height,
            pixels,
        })
    }

    /// An image whose pixel `(x, y)` is `f(x, y)`.
    pub fn from_fn(width: usize, height: usize, mut f: impl FnMut(usize, usize) -> P) -> Self {
        let mut pixels = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                pixels.push(f(x, y));
            }
        }
        Self {
            width,
            height,
            pixels,
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// `(width, height)`.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The pixels, row-major.
    pub fn pixels(&self) -> &[P] {
        &self.pixels
    }

    /// The pixels, row-major, mutable.
    pub fn pixels_mut(&mut self) -> &mut [P] {
        &mut self.pixels
    }

    /// Consumes the image, returning its pixels.
    pub fn into_pixels(self) -> Vec<P> {
        self.pixels
    }

    /// Pixel `(x, y)`. Panics outside the image, like slice indexing.
    #[inline]
    pub fn get(&self, x: usize, y: usize) -> P {
        self.pixels[y * self.width + x]
    }

    /// Sets pixel `(x, y)`.
    #[inline]
    pub fn set(&mut self, x: usize, y: usize, value: P) {
        self.pixels[y * self.width + x] = value;
    }

    /// A new image with `f` applied to every pixel.
    pub fn map<Q: Copy>(&self, f: impl Fn(P) -> Q) -> Image<Q> {
        Image {
            width: self.width,
            height: self.height,
            pixels: self.pixels.iter().map(|&p| f(p)).collect(),
        }
    }

    /// Row `y` as a slice.
    pub fn row(&self, y: usize) -> &[P] {
        &self.pixels[y * self.width..(y + 1) * self.width]
    }

    /// Whether `other` has the same width and height.
    pub fn same_size<Q>(&self, other: &Image<Q>) -> bool {
        self.width == other.width && self.height == other.height
    }
}

impl<P: Pixel> Image<P> {
    /// Bilinear sample at continuous coordinates `(x, y)` (pixel centres at integers).
    /// Non-finite coordinates give zero.
    #[inline]
    pub fn sample_bilinear(&self, x: f32, y: f32, border: Border) -> P {
        if !(x.is_finite() && y.is_finite()) || self.pixels.is_empty() {
            return P::zero();
        }
        let (w, h) = (self.width as i64, self.height as i64);
        // Far outside: avoid float-to-int saturation games.
        let limit = (w.max(h) + 2) as f32;
        let (x, y) = (
            x.clamp(-limit, w as f32 + limit),
            y.clamp(-limit, h as f32 + limit),
        );
        let (x0f, y0f) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0f, y - y0f);
        let (x0, y0) = (x0f as i64, y0f as i64);
        let mut acc = P::zero();
        for (dy, wy) in [(0, 1.0 - fy), (1, fy)] {
            for (dx, wx) in [(0, 1.0 - fx), (1, fx)] {
                let weight = wx * wy;
                if weight == 0.0 {
                    continue;
                }
                let (xi, yi) = (x0 + dx, y0 + dy);
                let inside = xi >= 0 && yi >= 0 && xi < w && yi < h;
                let p = match (inside, border) {
                    (true, _) => self.pixels[(yi * w + xi) as usize],
                    (false, Border::Zero) => continue,
                    (false, Border::Clamp) => {
                        let xc = xi.clamp(0, w - 1);
                        let yc = yi.clamp(0, h - 1);
                        self.pixels[(yc * w + xc) as usize]
                    }
                };
                acc = acc.add_scaled(p, weight);
            }
        }
        acc
    }

    /// Bicubic sample at continuous coordinates `(x, y)` (pixel centres at integers):
    /// Keys' cubic convolution with `a = −½` (Catmull–Rom), which reproduces quadratics
    /// and keeps more of a band-limited image's detail than bilinear when resampling by
    /// a fraction of a pixel; it may overshoot slightly at edges. Taps outside the image
    /// follow `border`. Non-finite coordinates give zero.
    #[inline]
    pub fn sample_bicubic(&self, x: f32, y: f32, border: Border) -> P {
        if !(x.is_finite() && y.is_finite()) || self.pixels.is_empty() {
            return P::zero();
        }
        let (w, h) = (self.width as i64, self.height as i64);
        let limit = (w.max(h) + 4) as f32;
        let (x, y) = (
            x.clamp(-limit, w as f32 + limit),
            y.clamp(-limit, h as f32 + limit),
        );
        let (x0f, y0f) = (x.floor(), y.floor());
        let (wx, wy) = (cubic_weights(x - x0f), cubic_weights(y - y0f));
        let (x0, y0) = (x0f as i64, y0f as i64);
        let mut acc = P::zero();
        for (j, &wyj) in wy.iter().enumerate() {
            let yi = y0 - 1 + j as i64;
            for (i, &wxi) in wx.iter().enumerate() {
                let xi = x0 - 1 + i as i64;
                let inside = xi >= 0 && yi >= 0 && xi < w && yi < h;
                let p = match (inside, border) {
                    (true, _) => self.pixels[(yi * w + xi) as usize],
                    (false, Border::Zero) => continue,
                    (false, Border::Clamp) => {
                        self.pixels[(yi.clamp(0, h - 1) * w + xi.clamp(0, w - 1)) as usize]
                    }
                };
                acc = acc.add_scaled(p, wxi * wyj);
            }
        }
        acc
    }

    /// Whether every channel of every pixel is finite.
    pub fn all_finite(&self) -> bool {
        self.pixels
            .iter()
            .all(|p| p.channels().iter().all(|c| c.is_finite()))
    }
}

/// Keys' cubic convolution weights (`a = −½`) of the taps at −1, 0, 1 and 2 for a sample
/// at fraction `t` in `[0, 1)` past tap 0; they sum to 1.
#[inline]
fn cubic_weights(t: f32) -> [f32; 4] {
    let (t2, t3) = (t * t, t * t * t);
    [
        -0.5 * t3 + t2 - 0.5 * t,
        1.5 * t3 - 2.5 * t2 + 1.0,
        -1.5 * t3 + 2.0 * t2 + 0.5 * t,
        0.5 * t3 - 0.5 * t2,
    ]
}

/// Rec. 709 luminance of linear RGB.
#[inline]
pub fn luminance(c: Rgb) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_hits_pixel_centres_exactly() {
        let img = Image::from_fn(4, 3, |x, y| (x + 10 * y) as f32);
        for y in 0..3 {
            for x in 0..4 {
                let s = img.sample_bilinear(x as f32, y as f32, Border::Zero);
                assert_eq!(s, img.get(x, y));
            }
        }
        // Half-way between (1,1)=11 and (2,1)=12.
        assert!((img.sample_bilinear(1.5, 1.0, Border::Clamp) - 11.5).abs() < 1e-6);
    }

    #[test]
    fn borders_behave_as_documented() {
        let img = Image::new(2, 2, 1.0f32);
        assert!((img.sample_bilinear(-0.5, 0.0, Border::Clamp) - 1.0).abs() < 1e-6);
        assert!((img.sample_bilinear(-0.5, 0.0, Border::Zero) - 0.5).abs() < 1e-6);
        assert_eq!(img.sample_bilinear(-5.0, 0.0, Border::Zero), 0.0);
        assert_eq!(img.sample_bilinear(f32::NAN, 0.0, Border::Clamp), 0.0);
        assert!((img.sample_bilinear(1e30, 0.0, Border::Clamp) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn bicubic_hits_pixel_centres_and_reproduces_quadratics() {
        let q = |x: f32, y: f32| 0.3 * x * x - 0.2 * x * y + 0.7 * y + 2.0;
        let img = Image::from_fn(9, 8, |x, y| q(x as f32, y as f32));
        for y in 0..8 {
            for x in 0..9 {
                assert!(
                    (img.sample_bicubic(x as f32, y as f32, Border::Zero) - img.get(x, y)).abs()
                        < 1e-5
                );
            }
        }
        // Away from the borders, between the samples, the cubic convolution is exact for
        // quadratics (Keys 1981), where bilinear is not.
        for (x, y) in [(3.25, 4.5), (4.7, 3.1), (2.5, 2.5)] {
            let (b, l) = (
                img.sample_bicubic(x, y, Border::Clamp),
                img.sample_bilinear(x, y, Border::Clamp),
            );
            assert!(
                (b - q(x, y)).abs() < 1e-4,
                "bicubic {b} vs {} at ({x}, {y})",
                q(x, y)
            );
            assert!(
                (l - q(x, y)).abs() > 1e-3,
                "bilinear should miss the curvature at ({x}, {y})"
            );
        }
        // Borders and hostile coordinates as bilinear.
        let flat = Image::new(3, 3, 1.0f32);
        assert!((flat.sample_bicubic(-0.5, 1.0, Border::Clamp) - 1.0).abs() < 1e-6);
        assert_eq!(flat.sample_bicubic(-9.0, 1.0, Border::Zero), 0.0);
        assert_eq!(flat.sample_bicubic(f32::NAN, 1.0, Border::Clamp), 0.0);
        assert!((flat.sample_bicubic(1e30, 1.0, Border::Clamp) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn from_vec_refuses_wrong_length() {
        let e = Image::from_vec(3, 3, vec![0.0f32; 8])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("pixels") && e.contains("8 pixels for a 3x3 image"),
            "{e}"
        );
    }
}
