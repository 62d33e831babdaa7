// Copied by battgen from codegen/backends/rust/support/convert_runtime.rs; do not edit.
//! Run-time support of the generated converters (`convert`): the loss report (a fixed array, no
//! allocation) and the arithmetic PX4's own C code does, as the Python package's
//! `convert/_runtime.py` emulates it: float16 rounding (IEEE, nearest even, finite values beyond
//! +-65504 clamped) and C's float to integer assignment as a Cortex-M FPU performs it (VCVT:
//! truncate, saturate to 32 bits, NaN 0; Rust's `as` does the same).

use crate::dronecan_wire::f16_value;

/// What did not survive a conversion (the Python `LossReport`'s kinds).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LossKind {
    /// A target field left at its "unknown" value.
    Unknown = 1,
    /// Source information with no place in the target.
    Dropped = 2,
    /// A value forced into range.
    Clamped = 3,
    /// A value quantised.
    Rounded = 4,
    /// A value the target cannot hold, written as its "unknown".
    Unrepresentable = 5,
}

impl LossKind {
    /// The name the Python report gives the kind.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Unknown => "unknown",
            Self::Dropped => "dropped",
            Self::Clamped => "clamped",
            Self::Rounded => "rounded",
            Self::Unrepresentable => "unrepresentable",
        }
    }
}

/// One entry of a loss report: its kind and the field (`"uorb.BatteryStatus.capacity"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Loss {
    /// What happened.
    pub kind: LossKind,
    /// The qualified field it happened to.
    pub field: &'static str,
}

/// The entries a report keeps; beyond them entries are counted in [`LossReport::missed`].
pub const LOSS_CAPACITY: usize = 96;

/// What did not survive a conversion: each (kind, field) once, in the order first seen.
#[derive(Clone, Copy, Debug)]
pub struct LossReport {
    entries: [Loss; LOSS_CAPACITY],
    count: usize,
    missed: usize,
}

impl Default for LossReport {
    fn default() -> Self {
        Self::new()
    }
}

impl LossReport {
    /// An empty report.
    #[must_use]
    pub const fn new() -> Self {
        let none = Loss {
            kind: LossKind::Unknown,
            field: "",
        };
        Self {
            entries: [none; LOSS_CAPACITY],
            count: 0,
            missed: 0,
        }
    }

    /// Forget every entry.
    pub fn clear(&mut self) {
        self.count = 0;
        self.missed = 0;
    }

    /// The entries kept, in the order first seen.
    #[must_use]
    pub fn entries(&self) -> &[Loss] {
        &self.entries[..self.count]
    }

    /// The entries that did not fit.
    #[must_use]
    pub const fn missed(&self) -> usize {
        self.missed
    }

    /// Nothing was lost.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        self.count == 0 && self.missed == 0
    }

    /// Add one entry, once.
    pub fn add(&mut self, kind: LossKind, field: &'static str) {
        if self
            .entries()
            .iter()
            .any(|e| e.kind == kind && e.field == field)
        {
            return;
        }
        if self.count < LOSS_CAPACITY {
            self.entries[self.count] = Loss { kind, field };
            self.count += 1;
        } else {
            self.missed += 1;
        }
    }

    /// Withdraw the entries of one kind and field (a later rule filled a field an earlier one left unknown).
    pub fn discard(&mut self, kind: LossKind, field: &str) {
        let mut j = 0;
        for i in 0..self.count {
            let e = self.entries[i];
            if !(e.kind == kind && e.field == field) {
                self.entries[j] = e;
                j += 1;
            }
        }
        self.count = j;
    }
}

/// The report one step of a converter's chain writes to: every step reports what it clamps and
/// rounds; what it drops and leaves unknown only where the chain says so.
pub(crate) struct Reports<'a> {
    rep: &'a mut LossReport,
    dropped: bool,
    unknown: bool,
}

impl<'a> Reports<'a> {
    pub(crate) fn new(rep: &'a mut LossReport, dropped: bool, unknown: bool) -> Self {
        Self {
            rep,
            dropped,
            unknown,
        }
    }

    pub(crate) fn add(&mut self, kind: LossKind, field: &'static str) {
        self.rep.add(kind, field);
    }

    pub(crate) fn dropped(&self) -> bool {
        self.dropped
    }

    pub(crate) fn add_d(&mut self, kind: LossKind, field: &'static str) {
        if self.dropped {
            self.rep.add(kind, field);
        }
    }

    pub(crate) fn add_u(&mut self, kind: LossKind, field: &'static str) {
        if self.unknown {
            self.rep.add(kind, field);
        }
    }

    pub(crate) fn discard_u(&mut self, kind: LossKind, field: &str) {
        if self.unknown {
            self.rep.discard(kind, field);
        }
    }

    /// The nearest integer (halves away from zero) clamped into `[lo, hi]`, what it changed
    /// reported (the Python `to_int`; NaN, which the Python converter refuses, gives `lo`).
    pub(crate) fn round_int(&mut self, x: f64, lo: i64, hi: i64, field: &'static str) -> i64 {
        let a = if x < 0.0 { -x } else { x };
        if x.is_nan() {
            return lo;
        }
        if a >= 9.2e18 {
            self.add(LossKind::Clamped, field);
            return if x > 0.0 { hi } else { lo };
        }
        let mut n = (a + 0.5) as i64; // the floor of a positive number
        if x < 0.0 {
            n = -n;
        }
        if n < lo || n > hi {
            self.add(LossKind::Clamped, field);
            return if n < lo { lo } else { hi };
        }
        let r = n as f64 - x;
        if (if r < 0.0 { -r } else { r }) > 1e-9 * (if a > 1.0 { a } else { 1.0 }) {
            self.add(LossKind::Rounded, field);
        }
        n
    }

    /// [`f16_round`], what it changed reported.
    pub(crate) fn f16_round(&mut self, x: f32, field: &'static str) -> f32 {
        let (y, loss) = f16_round(x);
        if let Some(kind) = loss {
            self.add(kind, field);
        }
        y
    }

    /// [`f16_round_d`], what it changed reported.
    pub(crate) fn f16_round_d(&mut self, x: f64, field: &'static str) -> f32 {
        let (y, loss) = f16_round_d(x);
        if let Some(kind) = loss {
            self.add(kind, field);
        }
        y
    }
}

const F16_MAX: f32 = 65504.0;

/// The float16 value nearest `x` (ties to even), a finite value beyond +-65504 clamped to it,
/// with what changed (clamped or rounded); infinity and NaN stay as they are.
#[must_use]
pub fn f16_round(x: f32) -> (f32, Option<LossKind>) {
    let u = x.to_bits();
    let sign = (u >> 16) & 0x8000;
    let a = u & 0x7FFF_FFFF;
    if a >= 0x7F80_0000 {
        return (x, None);
    }
    if !(-F16_MAX..=F16_MAX).contains(&x) {
        let y = if x > 0.0 { F16_MAX } else { -F16_MAX };
        return (y, Some(LossKind::Clamped));
    }
    let e = a >> 23;
    let h = if e >= 113 {
        // a normal half: 13 bits dropped, rounded to nearest even
        let mut h = ((e - 112) << 10) | ((a & 0x7F_FFFF) >> 13);
        let rest = a & 0x1FFF;
        if rest > 0x1000 || (rest == 0x1000 && h & 1 != 0) {
            h += 1;
        }
        h
    } else if e == 0 {
        0 // a float32 subnormal: below half the smallest half
    } else {
        // a subnormal half: the value in units of 2^-24, rounded to nearest even
        let sig = 0x80_0000 | (a & 0x7F_FFFF);
        let shift = 126 - e;
        if shift > 25 {
            0
        } else {
            let mut h = sig >> shift;
            let rest = sig & ((1 << shift) - 1);
            let half = 1 << (shift - 1);
            if rest > half || (rest == half && h & 1 != 0) {
                h += 1;
            }
            h
        }
    };
    let y = f16_value((sign | h) as u16);
    (
        y,
        if y == x {
            None
        } else {
            Some(LossKind::Rounded)
        },
    )
}

/// The float16 nearest a double (ties to even), as Python's struct `"e"` rounds it: the double is
/// first made a float rounded to odd (exact for the half's 11 bits), then rounded as [`f16_round`].
#[must_use]
pub fn f16_round_d(x: f64) -> (f32, Option<LossKind>) {
    if x.is_nan() || x.is_infinite() {
        return (x as f32, None);
    }
    if !(-65504.0..=65504.0).contains(&x) {
        let y = if x > 0.0 { F16_MAX } else { -F16_MAX };
        return (y, Some(LossKind::Clamped));
    }
    let f = x as f32;
    let mut u = f.to_bits();
    if f64::from(f) != x {
        if (f > 0.0 && f64::from(f) > x) || (f < 0.0 && f64::from(f) < x) {
            u -= 1; // toward zero: the float below the double's magnitude
        }
        u |= 1; // sticky: round to odd
    }
    let (y, _) = f16_round(f32::from_bits(u));
    (
        y,
        if f64::from(y) == x {
            None
        } else {
            Some(LossKind::Rounded)
        },
    )
}

/// C's `roundf`: halves away from zero, the sign kept (-0.3 gives -0.0).
#[must_use]
pub fn roundf(x: f32) -> f32 {
    let u = x.to_bits();
    let a = u & 0x7FFF_FFFF;
    if a >= 0x4B00_0000 {
        return x; // 2^23 and beyond (infinity, NaN): already whole
    }
    let r = (f64::from(f32::from_bits(a)) + 0.5) as i32 as f32; // exact in f64: floor(a + 0.5)
    f32::from_bits(r.to_bits() | (u & 0x8000_0000))
}

/// The magnitude of `x` (its sign bit cleared).
#[must_use]
pub fn absf(x: f32) -> f32 {
    f32::from_bits(x.to_bits() & 0x7FFF_FFFF)
}

/// Whether an integer field that kept `kept` of `x` lost it (the Python `c_float_to_int`'s
/// "does not fit": NaN is no loss, an infinity always is).
#[must_use]
pub fn float_int_lost(x: f32, kept: i64) -> bool {
    if x.is_nan() {
        return false;
    }
    if x.is_infinite() || !(-9_223_372_036_854_775_808.0..9_223_372_036_854_775_808.0).contains(&x)
    {
        return true;
    }
    x as i64 != kept
}

/// Two texts equal up to the first NUL (as Python compares the strings).
#[must_use]
pub fn same_chars(a: &[u8], b: &[u8]) -> bool {
    for i in 0..a.len().max(b.len()) {
        let x = a.get(i).copied().unwrap_or(0);
        let y = b.get(i).copied().unwrap_or(0);
        if x != y {
            return false;
        }
        if x == 0 {
            return true;
        }
    }
    true
}

/// Bytes as Python's `bytes.decode("utf-8", "replace")` and `str.encode("utf-8")` leave them:
/// valid UTF-8 kept, each maximal invalid subpart replaced by U+FFFD (EF BF BD). `out` has room for
/// `3 * input.len()` bytes; returns how many it holds.
pub fn utf8_replace(input: &[u8], out: &mut [u8]) -> usize {
    let n = input.len();
    let (mut i, mut o) = (0, 0);
    while i < n {
        let b = input[i];
        let (mut lo, mut hi) = (0x80u8, 0xBFu8);
        if b < 0x80 {
            out[o] = b;
            o += 1;
            i += 1;
            continue;
        }
        let need: usize = if (0xC2..=0xDF).contains(&b) {
            1
        } else if (0xE0..=0xEF).contains(&b) {
            lo = if b == 0xE0 { 0xA0 } else { 0x80 };
            hi = if b == 0xED { 0x9F } else { 0xBF };
            2
        } else if (0xF0..=0xF4).contains(&b) {
            lo = if b == 0xF0 { 0x90 } else { 0x80 };
            hi = if b == 0xF4 { 0x8F } else { 0xBF };
            3
        } else {
            0 // never a start byte
        };
        let mut k = 1;
        while k <= need {
            if i + k >= n {
                break;
            }
            let c = input[i + k];
            let (l, h) = if k == 1 { (lo, hi) } else { (0x80, 0xBF) };
            if c < l || c > h {
                break;
            }
            k += 1;
        }
        if need > 0 && k > need {
            out[o..=o + need].copy_from_slice(&input[i..=i + need]);
            o += need + 1;
            i += need + 1;
        } else {
            out[o..o + 3].copy_from_slice(&[0xEF, 0xBF, 0xBD]);
            o += 3;
            i += if need > 0 { k } else { 1 };
        }
    }
    o
}
