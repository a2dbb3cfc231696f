//! The user's style (docs/method.md "Style control"): a weight per tone, and the mixed
//! cost-to-go the selector reads through it.

use super::tables::PolicyTables;

/// Most tones a [`Style`] mixes (and a blob carries).
pub const MAX_TONES: usize = 8;

/// The user's style: a weight per tone and the neutral weight (they sum to 1). Only built
/// through [`Style::new`], so the weights are always finite, non-negative and normalized.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    neutral: f32,
    tone: [f32; MAX_TONES],
    tones: usize,
}

/// Why style weights were refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StyleError {
    /// More weights than the tables have tones.
    TooManyWeights {
        /// Weights given.
        given: u32,
        /// Tones of the tables.
        tones: u32,
    },
    /// A weight is NaN or infinite.
    NotFinite {
        /// Its index.
        tone: u32,
    },
    /// A weight is negative.
    Negative {
        /// Its index.
        tone: u32,
    },
}

impl core::fmt::Display for StyleError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::TooManyWeights { given, tones } => {
                write!(f, "{given} style weights for {tones} tones")
            }
            Self::NotFinite { tone } => write!(f, "style weight {tone} is not a finite number"),
            Self::Negative { tone } => write!(f, "style weight {tone} is negative"),
        }
    }
}

impl core::error::Error for StyleError {}

impl Style {
    /// Neutral: the policy's own tables.
    pub const NEUTRAL: Self = Self {
        neutral: 1.0,
        tone: [0.0; MAX_TONES],
        tones: 0,
    };

    /// The style with weight `weights[m]` on tone `m` (at most [`MAX_TONES`]; missing tones
    /// weigh 0). Weights must be finite and non-negative; if they sum to more than 1 they are
    /// divided by their sum, and the neutral tables get what is left of 1.
    pub fn new(weights: &[f32]) -> Result<Self, StyleError> {
        if weights.len() > MAX_TONES {
            return Err(StyleError::TooManyWeights {
                given: weights.len() as u32,
                tones: MAX_TONES as u32,
            });
        }
        let mut max = 0.0f32;
        for (m, &w) in weights.iter().enumerate() {
            if !w.is_finite() {
                return Err(StyleError::NotFinite { tone: m as u32 });
            }
            if w < 0.0 {
                return Err(StyleError::Negative { tone: m as u32 });
            }
            max = max.max(w);
        }
        if max == 0.0 {
            return Ok(Self::NEUTRAL);
        }
        // Relative to the largest weight the sum is 1..=8, so it cannot overflow.
        let mut st = Self::NEUTRAL;
        let mut rel = 0.0f32;
        for (t, &w) in st.tone.iter_mut().zip(weights) {
            *t = w;
            rel += w / max;
        }
        st.tones = weights.len();
        if rel > 1.0 / max {
            // The weights sum to more than 1: divide by the sum (as `(w / max) / rel`).
            for t in st.tone.iter_mut() {
                *t = *t / max / rel;
            }
            st.neutral = 0.0;
        } else {
            st.neutral = 1.0 - st.tone.iter().sum::<f32>();
        }
        Ok(st)
    }

    /// The neutral tables' weight.
    pub fn neutral(&self) -> f32 {
        self.neutral
    }

    /// The tones' weights (as many as were given).
    pub fn weights(&self) -> &[f32] {
        &self.tone[..self.tones.min(MAX_TONES)]
    }

    /// Whether only the neutral tables are read.
    pub fn is_neutral(&self) -> bool {
        self.tones == 0
    }

    /// `d_0 neutral() + sum_m d_m tone(m)` over the first `tones` tones, skipping zero weights;
    /// exactly `neutral()` for the neutral style.
    #[inline]
    fn mix(&self, tones: usize, neutral: impl Fn() -> f32, tone: impl Fn(usize) -> f32) -> f32 {
        if self.is_neutral() {
            return neutral();
        }
        let mut v = if self.neutral > 0.0 {
            self.neutral * neutral()
        } else {
            0.0
        };
        for (m, &w) in self.weights().iter().enumerate().take(tones) {
            if w > 0.0 {
                v += w * tone(m);
            }
        }
        v
    }

    /// `b . U(c)` with the tables mixed by these weights: `d_0 (b . U(c)) + sum_m d_m (b .
    /// U^m(c))`, exactly `t.u_dot(c, b)` when neutral. Each table is read once per candidate
    /// (a row of S values), so a mix of M tones costs M + 1 dot products.
    #[inline]
    pub(super) fn u_dot<T: PolicyTables + ?Sized>(&self, t: &T, c: usize, b: &[f32]) -> f32 {
        self.mix(t.tones(), || t.u_dot(c, b), |m| t.tone_u_dot(m, c, b))
    }

    /// `b . U_cont(e)` mixed like [`u_dot`](Self::u_dot).
    #[inline]
    pub(super) fn u_cont_dot<T: PolicyTables + ?Sized>(&self, t: &T, e: usize, b: &[f32]) -> f32 {
        self.mix(
            t.tones(),
            || t.u_cont_dot(e, b),
            |m| t.tone_u_cont_dot(m, e, b),
        )
    }
}
