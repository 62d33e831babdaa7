// Copied by battgen from codegen/backends/rust/support/same.rs; do not edit.
//! Equality in which NaN equals NaN: a NaN sentinel ("unknown") is the same data as another NaN,
//! so a message decoded from its own encoding compares equal to itself (Python's generated `__eq__`).

/// Field-by-field sameness; floats compare NaN-equal.
pub trait Same {
    /// True when both hold the same data.
    fn same(&self, other: &Self) -> bool;
}

macro_rules! exact {
    ($($t:ty),*) => {$(
        impl Same for $t {
            fn same(&self, other: &Self) -> bool {
                self == other
            }
        }
    )*};
}

exact!(bool, u8, u16, u32, u64, i8, i16, i32, i64);

impl Same for f32 {
    fn same(&self, other: &Self) -> bool {
        self == other || (self.is_nan() && other.is_nan())
    }
}

impl Same for f64 {
    fn same(&self, other: &Self) -> bool {
        self == other || (self.is_nan() && other.is_nan())
    }
}

impl<T: Same> Same for [T] {
    fn same(&self, other: &Self) -> bool {
        self.len() == other.len() && self.iter().zip(other).all(|(a, b)| a.same(b))
    }
}

impl<T: Same, const N: usize> Same for [T; N] {
    fn same(&self, other: &Self) -> bool {
        self[..].same(&other[..])
    }
}
