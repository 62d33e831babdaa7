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
