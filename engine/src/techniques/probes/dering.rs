//! Deringing of the probes' SH: a window h_l multiplies band l's coefficients (h₀ = 1), as in
//! Sloan's "Stupid Spherical Harmonics (SH) Tricks" (2008, section on windowing). Nine
//! coefficients of a small, bright light ring: the irradiance of a point light in direction s is
//! P · k₂(n·s) with k₂(t) = 1/4 + t/2 + 5/32 (3t² − 1) (the clamped cosine max(t, 0) projected
//! to bands 0–2), which dips to −0.0396 (3.7% of its peak, 1.0625) around 122° from the light.
//! With a window, k(t) = 1/4 + h₁ t/2 + h₂ 5/32 (3t² − 1).
//!
//! - [`Dering::Hanning`]`(w)`: h_l = (1 + cos(π l / w)) / 2 for l < w, else 0;
//! - [`Dering::Lanczos`]`(w)`: h_l = sinc(π l / w);
//! - [`Dering::NonNegative`]: h₁ = 0.86, h₂ = 0.89, the window of least squared error against the
//!   clamped cosine among those whose kernel is ≥ 0 everywhere (a grid search over h₁, h₂ in
//!   steps of 0.01; the kernel's discriminant 0.43² − 4 · 0.4172 · 0.1109 is < 0). Since
//!   E(n) = ∫ L(ω) k(n·ω) dω with L ≥ 0, the irradiance is then never negative, whatever the
//!   light: the failure test's guarantee. Hanning and Lanczos only shrink the negative lobe
//!   (to −2.1% to −2.7% of the peak at w = 4–5) and blur less.
use crate::error::{Error, Result};
use crate::sh::ShRgb9;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Dering {
    /// The SH as captured (the default); the shading clamps negative irradiance at 0.
    #[default]
    Off,
    Hanning(f32),
    Lanczos(f32),
    NonNegative,
}

impl Dering {
    /// `off`, `nonnegative`, `hanning:W` or `lanczos:W` (W > 0, in bands).
    pub fn parse(text: &str) -> Result<Dering> {
        let bad = || {
            Error::InvalidArgument(format!(
                "deringing window \"{text}\": expected off, nonnegative, hanning:W or lanczos:W with a width W > 0"
            ))
        };
        let width = |w: &str| w.parse::<f32>().ok().filter(|w| w.is_finite() && *w > 0.0).ok_or_else(bad);
        match text.split_once(':') {
            None if text == "off" => Ok(Dering::Off),
            None if text == "nonnegative" => Ok(Dering::NonNegative),
            Some(("hanning", w)) => Ok(Dering::Hanning(width(w)?)),
            Some(("lanczos", w)) => Ok(Dering::Lanczos(width(w)?)),
            _ => Err(bad()),
        }
    }

    /// h₀, h₁, h₂.
    pub fn weights(self) -> [f32; 3] {
        let window = |f: &dyn Fn(f32) -> f32| [1.0, f(1.0), f(2.0)];
        match self {
            Dering::Off => [1.0; 3],
            Dering::Hanning(w) => {
                window(&|l| if l < w { 0.5 * (1.0 + (std::f32::consts::PI * l / w).cos()) } else { 0.0 })
            }
            Dering::Lanczos(w) => window(&|l| {
                let x = std::f32::consts::PI * l / w;
                x.sin() / x
            }),
            Dering::NonNegative => [1.0, 0.86, 0.89],
        }
    }

    /// `sh` with band l scaled by h_l.
    pub fn apply(self, sh: &ShRgb9) -> ShRgb9 {
        let h = self.weights();
        let mut out = *sh;
        for (i, c) in out.c.iter_mut().enumerate() {
            let band = if i == 0 {
                0
            } else if i < 4 {
                1
            } else {
                2
            };
            *c = c.map(|v| v * h[band]);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The windowed kernel k(t) of the module documentation.
    fn kernel(h: [f32; 3], t: f32) -> f32 {
        0.25 + h[1] * t / 2.0 + h[2] * 5.0 / 32.0 * (3.0 * t * t - 1.0)
    }

    fn kernel_min(dering: Dering) -> f32 {
        (0..=2000).map(|i| kernel(dering.weights(), i as f32 / 1000.0 - 1.0)).fold(f32::MAX, f32::min)
    }

    #[test]
    fn windows_shrink_or_remove_the_negative_lobe() {
        let raw = kernel_min(Dering::Off);
        assert!((raw + 0.0396).abs() < 1e-3, "raw kernel minimum {raw}");
        assert!(kernel_min(Dering::NonNegative) >= 0.0);
        for dering in [Dering::Hanning(4.0), Dering::Lanczos(4.0)] {
            let min = kernel_min(dering);
            assert!(min < 0.0 && min > 0.6 * raw, "{dering:?}: {min} against {raw}");
        }
    }

    #[test]
    fn parse_names_bad_windows() {
        assert_eq!(Dering::parse("hanning:4").unwrap(), Dering::Hanning(4.0));
        assert_eq!(Dering::parse("lanczos:2.5").unwrap(), Dering::Lanczos(2.5));
        assert_eq!(Dering::parse("off").unwrap(), Dering::Off);
        assert_eq!(Dering::parse("nonnegative").unwrap(), Dering::NonNegative);
        for bad in ["hanning", "hanning:0", "gauss:2", "lanczos:nan", ""] {
            let error = Dering::parse(bad).unwrap_err().to_string();
            assert!(error.contains("deringing window"), "{bad}: {error}");
        }
    }
}
