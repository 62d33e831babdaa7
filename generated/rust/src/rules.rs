// Copied by battgen from codegen/backends/rust/support/rules.rs; do not edit.
//! What the cross-field rules of the validators need to read values as battgen's Python validators
//! do: Python's indexing, true division and `range()` kept to the message's arrays. Where Python
//! raises (and its validator skips the rule), these give `None`.

/// Python's `seq[i]`: a negative `i` counts from the end; beyond the sequence, `None`.
#[must_use]
pub fn at<T: Copy>(seq: &[T], i: i128) -> Option<T> {
    let len = i128::try_from(seq.len()).ok()?;
    let i = if i < 0 { i + len } else { i };
    seq.get(usize::try_from(i).ok()?).copied()
}

/// Python's `a / b` on numbers: `None` where Python raises ZeroDivisionError.
#[must_use]
pub fn div(a: f64, b: f64) -> Option<f64> {
    if b == 0.0 {
        None
    } else {
        Some(a / b)
    }
}

/// A rule's `range(start, stop)` kept to `0..limit`, the indices an array of the message can have:
/// a corrupt count in a message must not make the validator loop for long.
#[must_use]
pub fn span(start: i128, stop: i128, limit: i128) -> core::ops::Range<i128> {
    start.max(0)..stop.min(limit)
}

/// The array position a problem names (`None` for an index no array has).
#[must_use]
pub fn position(i: i128) -> Option<usize> {
    usize::try_from(i).ok()
}

/// Python's comparison of an integer with a float: exact (the integer is not rounded to an f64, so
/// 2^53 + 1 is above 2^53 as a float), `None` for NaN (every comparison with it false but `!=`).
#[must_use]
pub fn int_float(i: i128, f: f64) -> Option<core::cmp::Ordering> {
    use core::cmp::Ordering;
    const TOP: f64 = 170_141_183_460_469_231_731_687_303_715_884_105_728.0; // 2^127: beyond every i128
    if f.is_nan() {
        return None;
    }
    if f >= TOP {
        return Some(Ordering::Less);
    }
    if f < -TOP {
        return Some(Ordering::Greater);
    }
    let whole = f as i128; // toward zero, exact below 2^127
    Some(match i.cmp(&whole) {
        Ordering::Equal => {
            let fraction = f - whole as f64; // exact: a float less its integer part
            if fraction > 0.0 {
                Ordering::Less
            } else if fraction < 0.0 {
                Ordering::Greater
            } else {
                Ordering::Equal
            }
        }
        other => other,
    })
}

/// [`int_float`] the other way round: a float compared with an integer.
#[must_use]
pub fn float_int(f: f64, i: i128) -> Option<core::cmp::Ordering> {
    int_float(i, f).map(core::cmp::Ordering::reverse)
}
