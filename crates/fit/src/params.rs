//! The map between the optimiser's unconstrained vector `u` and the
//! physical parameters: a logistic for box bounds, `exp` for the positive
//! scale. All of the fit's bound handling lives here.

use brtf_model::{Shape, ShapeArg};

/// What one free parameter drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// All three colour arguments at once (grey fit).
    Gray,
    /// One flat argument of the material's shape (index into its
    /// argument list, [`Shape::args`]).
    Arg(usize),
    /// The free overall scale factor for raw-signal data.
    Scale,
}

/// One free parameter with its physical range (both bounds infinite: the
/// parameter is unbounded, as the orientation angle).
#[derive(Debug, Clone, PartialEq)]
pub struct Slot {
    /// Name as in the fit tables (`red`, `spec`, `rough`, `scale`, ...).
    pub name: String,
    /// What it drives.
    pub target: Target,
    /// Lower physical bound.
    pub lo: f64,
    /// Upper physical bound (infinite for the scale).
    pub hi: f64,
}

/// Lowest roughness the fit may reach: just above rtrace's roughness-0
/// switch (α ≤ 0.001), below which the lobe vanishes from the direct term.
pub const MIN_ROUGHNESS: f64 = 0.002;
/// Highest roughness: beyond this the Gaussian-slope model is meaningless.
pub const MAX_ROUGHNESS: f64 = 1.0;

/// The free parameters of one fit.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamMap {
    /// The shape being fitted.
    pub shape: Shape,
    /// The free parameters, in optimiser order.
    pub slots: Vec<Slot>,
    /// Material arguments not fitted (colour fixed to 1 under a free scale).
    pub fixed: Vec<f64>,
}

impl ParamMap {
    /// The free parameters for `shape`: a grey colour (`gray`) or RGB, the
    /// other flat arguments, and optionally a free scale (which fixes the
    /// colour to 1, since only scale × colour is identified).
    pub fn new(shape: Shape, gray: bool, free_scale: bool) -> ParamMap {
        let names = shape.param_names();
        let roles = shape.args();
        let mut slots = Vec::new();
        let mut fixed = vec![0.0; shape.n_args()];
        if free_scale {
            fixed[..3].copy_from_slice(&[1.0; 3]);
            slots.push(Slot {
                name: "scale".into(),
                target: Target::Scale,
                lo: 0.0,
                hi: f64::INFINITY,
            });
        } else if gray {
            slots.push(Slot {
                name: "gray".into(),
                target: Target::Gray,
                lo: 0.0,
                hi: 1.0,
            });
        } else {
            for (i, name) in names.iter().enumerate().take(3) {
                slots.push(Slot {
                    name: name.clone(),
                    target: Target::Arg(i),
                    lo: 0.0,
                    hi: 1.0,
                });
            }
        }
        for (i, name) in names.iter().enumerate().skip(3) {
            let (lo, hi) = match roles[i] {
                ShapeArg::RoughU(_) | ShapeArg::RoughV(_) => (MIN_ROUGHNESS, MAX_ROUGHNESS),
                ShapeArg::Orient => (f64::NEG_INFINITY, f64::INFINITY),
                _ => (0.0, 1.0),
            };
            slots.push(Slot {
                name: name.clone(),
                target: Target::Arg(i),
                lo,
                hi,
            });
        }
        ParamMap {
            shape,
            slots,
            fixed,
        }
    }

    /// The same map with roughness bounded below by `min` (never below
    /// [`MIN_ROUGHNESS`]).
    pub fn with_min_roughness(mut self, min: f64) -> ParamMap {
        let min = min.clamp(MIN_ROUGHNESS, 0.5 * MAX_ROUGHNESS);
        for slot in &mut self.slots {
            if slot.name.starts_with("rough") {
                slot.lo = min;
            }
        }
        self
    }

    /// Number of free parameters.
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// True when nothing is free.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Index of the slot driving material argument `arg`, if free.
    pub fn slot_of_arg(&self, arg: usize) -> Option<usize> {
        self.slots.iter().position(|s| match s.target {
            Target::Arg(a) => a == arg,
            Target::Gray => arg < 3,
            Target::Scale => false,
        })
    }

    /// Physical value of slot `i` for unconstrained `u`, and dp/du.
    pub fn to_physical(&self, i: usize, u: f64) -> (f64, f64) {
        let s = &self.slots[i];
        if s.lo.is_infinite() {
            return (u, 1.0);
        }
        if s.hi.is_infinite() {
            let p = s.lo + u.exp();
            return (p, u.exp());
        }
        // Past ±SATURATED the parameter sits at its bound (to 1e-7 of its
        // range) and stops moving: without this, LM would crawl towards
        // the bound for dozens of passes, since each step gains only a
        // constant in u while the column shrinks like e^-|u|.
        let saturated = u.abs() > SATURATED;
        let sig = logistic(u.clamp(-SATURATED, SATURATED));
        let p = s.lo + (s.hi - s.lo) * sig;
        let dp_du = if saturated {
            0.0
        } else {
            (s.hi - s.lo) * sig * (1.0 - sig)
        };
        (p, dp_du)
    }

    /// Unconstrained value for physical `p` (clamped just inside the bounds).
    pub fn to_unconstrained(&self, i: usize, p: f64) -> f64 {
        let s = &self.slots[i];
        if s.lo.is_infinite() {
            return p;
        }
        if s.hi.is_infinite() {
            return (p - s.lo).max(1e-300).ln();
        }
        let t = ((p - s.lo) / (s.hi - s.lo)).clamp(1e-6, 1.0 - 1e-6);
        (t / (1.0 - t)).ln()
    }

    /// Material arguments and scale for physical parameters `p`.
    pub fn material_args(&self, p: &[f64]) -> (Vec<f64>, f64) {
        let mut args = self.fixed.clone();
        let mut scale = 1.0;
        for (slot, &value) in self.slots.iter().zip(p) {
            match slot.target {
                Target::Gray => args[..3].copy_from_slice(&[value; 3]),
                Target::Arg(a) => args[a] = value,
                Target::Scale => scale = value,
            }
        }
        (args, scale)
    }

    /// True when physical value `p` of slot `i` sits at a bound.
    pub fn at_bound(&self, i: usize, p: f64) -> bool {
        let s = &self.slots[i];
        if s.lo.is_infinite() {
            return false;
        }
        if s.hi.is_infinite() {
            return p <= s.lo + 1e-12;
        }
        let t = (p - s.lo) / (s.hi - s.lo);
        !(1e-4..=1.0 - 1e-4).contains(&t)
    }
}

/// |u| beyond which a bounded parameter is at its bound: logistic(−16) ≈
/// 1.1e-7 of the range.
const SATURATED: f64 = 20.0;

fn logistic(u: f64) -> f64 {
    if u >= 0.0 {
        1.0 / (1.0 + (-u).exp())
    } else {
        let e = u.exp();
        e / (1.0 + e)
    }
}
