//! The block spectra of a search pass, held as 16-bit integers with one scale per slice.
//!
//! A pass keeps every block's spectrum at every fractional Doppler offset until every PRN
//! of the search has read it (10 ms x 50 at 4 MHz: 4 M complex values, 32 MB as f32). Each
//! slice (one block, offset and residue: `spec_len` values) is stored as `round(x / s)` in
//! i16 with `s = max(|re|, |im|) / 32767` over the slice, half the memory. The rounding error
//! is uniform with variance `s^2 / 12` per component: for noise-like spectra (Gaussian, the
//! largest of 4000 values about 4.5 sigma) that is 88 dB below the noise power; a spectral
//! line 100 times the noise amplitude (a strong DC offset) leaves it 48 dB below. The search
//! loses nothing it can measure (see the test).

use num_complex::Complex32;

/// Block spectra: slices of `slice_len` complex values with their scales.
#[derive(Debug, Default)]
pub(super) struct Spectra {
    values: Vec<[i16; 2]>,
    scales: Vec<f32>,
    slice_len: usize,
}

impl Spectra {
    /// Makes room for `slices` slices of `slice_len` values (contents unspecified).
    pub(super) fn resize(&mut self, slices: usize, slice_len: usize) {
        self.slice_len = slice_len;
        self.values.resize(slices * slice_len, [0, 0]);
        self.scales.resize(slices, 0.0);
    }

    /// The slices, each with its scale, to be written in parallel.
    pub(super) fn slices_mut(&mut self) -> impl Iterator<Item = (&mut [[i16; 2]], &mut f32)> {
        self.values
            .chunks_mut(self.slice_len.max(1))
            .zip(self.scales.iter_mut())
    }

    /// Slice `i`: its values and scale (value = integer x scale).
    pub(super) fn slice(&self, i: usize) -> (&[[i16; 2]], f32) {
        let n = self.slice_len;
        (&self.values[i * n..(i + 1) * n], self.scales[i])
    }
}

/// Stores `src` into `dst` (same length) as integers; returns the scale (AVX2-wide loops where
/// the CPU has it: [`super::wide`]).
pub(super) fn quantize(src: &[Complex32], dst: &mut [[i16; 2]]) -> f32 {
    let peak = super::wide::peak_component(src);
    if !(peak > 0.0 && peak.is_finite()) {
        dst.fill([0, 0]);
        return 0.0;
    }
    let scale = peak / f32::from(i16::MAX);
    let inv = 1.0 / scale;
    // |x / scale| <= 32767 (rounding stays within i16).
    super::wide::round_scaled(src, inv, dst);
    scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantized_slices_keep_the_values_to_a_half_step() {
        let src: Vec<Complex32> = (0..4000)
            .map(|k| {
                let t = k as f32 * 0.37;
                Complex32::new(1e3 * t.sin(), -250.0 * (1.7 * t).cos())
            })
            .collect();
        let mut s = Spectra::default();
        s.resize(2, 4000);
        let mut scales = Vec::new();
        for (i, (dst, sc)) in s.slices_mut().enumerate() {
            *sc = quantize(&src, dst);
            scales.push(*sc);
            if i == 1 {
                dst.fill([0, 0]);
            }
        }
        let (v, scale) = s.slice(0);
        assert!((scale - 1e3 / 32767.0).abs() < 1e-3 * scale, "{scale}");
        for (x, q) in src.iter().zip(v) {
            assert!((x.re - f32::from(q[0]) * scale).abs() <= 0.5001 * scale);
            assert!((x.im - f32::from(q[1]) * scale).abs() <= 0.5001 * scale);
        }
        // An all-zero (or non-finite) slice stores zeros with scale 0.
        let mut z = [[1i16, 1]; 3];
        assert_eq!(quantize(&[Complex32::new(0.0, 0.0); 3], &mut z), 0.0);
        assert_eq!(z, [[0, 0]; 3]);
    }
}
