//! Band-limited resampling by windowed-sinc interpolation.
//!
//! Every output sample `n` sits at input time `t = n · from / to` and is the sum of the
//! input samples within a fixed number of zero crossings of `t`, weighted by a sinc low-pass
//! filter (cut off just below the lower of the two Nyquist frequencies, so downsampling
//! does not alias) shaped by a Kaiser window (β = 8.6, about 90 dB of stop-band
//! rejection). The weights of each output sample are normalised to sum to one, so a
//! constant signal keeps its exact level. Samples outside the input count as silence. The
//! weights depend only on the output sample's phase between two input samples, of which
//! there are `to / gcd(from, to)` (1 for 48 kHz → 16 kHz, 160 for 44.1 kHz): they are
//! computed once per phase.

use std::f64::consts::PI;

/// Zero crossings of the sinc on each side of the centre.
const ZERO_CROSSINGS: f64 = 24.0;
/// The cut-off as a fraction of the lower Nyquist frequency: the rest is the transition band.
const ROLLOFF: f64 = 0.92;
const KAISER_BETA: f64 = 8.6;

/// The number of output samples for `len` input samples: `len · to / from`, rounded.
pub fn output_len(len: usize, from: u32, to: u32) -> usize {
    let (len, from, to) = (len as u128, u128::from(from), u128::from(to));
    ((len * to + from / 2) / from) as usize
}

/// Phase tables larger than this are not precomputed (rates with a tiny common divisor);
/// the kernel is then evaluated for every output sample.
const MAX_PHASES: u64 = 4096;

/// Resample mono `input` from `from` Hz to `to` Hz.
pub fn resample(input: &[f32], from: u32, to: u32) -> Vec<f32> {
    if from == to || input.is_empty() || from == 0 || to == 0 {
        return input.to_vec();
    }
    let filter = Filter::new(from, to);
    let n_out = output_len(input.len(), from, to);
    let last = input.len() as i64 - 1;
    let mut out = Vec::with_capacity(n_out);
    let mut scratch = Vec::new();
    for n in 0..n_out {
        // Exact input position n · from / to: an input index and a phase (remainder / to).
        let num = n as u128 * u128::from(from);
        let centre = (num / u128::from(to)) as i64;
        let remainder = (num % u128::from(to)) as u64;
        let taps = filter.taps(remainder, &mut scratch);
        let first = centre - filter.reach;
        let mut acc = 0.0f64;
        for (j, w) in taps.iter().enumerate() {
            let k = first + j as i64;
            if (0..=last).contains(&k) {
                acc += w * f64::from(input[k as usize]);
            }
        }
        out.push(acc as f32);
    }
    out
}

/// The filter's weights for every phase, each set normalised to sum to one.
struct Filter {
    to: u64,
    cutoff: f64,
    half: f64,
    norm: f64,
    /// Taps on each side of the centre sample.
    reach: i64,
    /// Remainders n·from mod to are multiples of gcd(from, to): phase = remainder / gcd.
    gcd: u64,
    table: Option<Vec<Vec<f64>>>,
}

impl Filter {
    fn new(from: u32, to: u32) -> Filter {
        let ratio = f64::from(to) / f64::from(from);
        // Cut-off in cycles per input sample.
        let cutoff = 0.5 * ratio.min(1.0) * ROLLOFF;
        // Half the filter's length, in input samples.
        let half = ZERO_CROSSINGS / (2.0 * cutoff);
        let gcd = gcd(u64::from(from), u64::from(to));
        let mut filter = Filter {
            to: u64::from(to),
            cutoff,
            half,
            norm: bessel_i0(KAISER_BETA),
            reach: half.ceil() as i64,
            gcd,
            table: None,
        };
        let phases = u64::from(to) / gcd;
        if phases <= MAX_PHASES {
            let mut table = Vec::with_capacity(phases as usize);
            for p in 0..phases {
                let mut taps = Vec::new();
                filter.compute(p * gcd, &mut taps);
                table.push(taps);
            }
            filter.table = Some(table);
        }
        filter
    }

    fn taps<'a>(&'a self, remainder: u64, scratch: &'a mut Vec<f64>) -> &'a [f64] {
        match &self.table {
            Some(table) => &table[(remainder / self.gcd) as usize],
            None => {
                self.compute(remainder, scratch);
                scratch
            }
        }
    }

    /// The normalised weights of input samples centre-reach ..= centre+reach for an output
    /// sample `remainder / to` past the centre.
    fn compute(&self, remainder: u64, taps: &mut Vec<f64>) {
        let frac = remainder as f64 / self.to as f64;
        taps.clear();
        taps.extend(
            (-self.reach..=self.reach)
                .map(|k| kernel(k as f64 - frac, self.cutoff, self.half, self.norm)),
        );
        let sum: f64 = taps.iter().sum();
        if sum.abs() > 1e-12 {
            taps.iter_mut().for_each(|w| *w /= sum);
        }
    }
}

fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a.max(1)
}

/// The windowed sinc at `x` input samples from the centre.
fn kernel(x: f64, cutoff: f64, half: f64, norm: f64) -> f64 {
    if x.abs() >= half {
        return 0.0;
    }
    let arg = 2.0 * cutoff * x;
    let sinc = if arg.abs() < 1e-12 {
        1.0
    } else {
        (PI * arg).sin() / (PI * arg)
    };
    let r = x / half;
    let window = bessel_i0(KAISER_BETA * (1.0 - r * r).max(0.0).sqrt()) / norm;
    2.0 * cutoff * sinc * window
}

/// The modified Bessel function of the first kind, order zero (power series).
fn bessel_i0(x: f64) -> f64 {
    let (mut sum, mut term) = (1.0, 1.0);
    let q = x * x / 4.0;
    for k in 1..64 {
        term *= q / (k as f64 * k as f64);
        sum += term;
        if term < sum * 1e-17 {
            break;
        }
    }
    sum
}

#[cfg(test)]
#[path = "resample_tests.rs"]
mod tests;
