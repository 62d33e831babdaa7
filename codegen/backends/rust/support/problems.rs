//! What a validator reports: every problem of a message in a fixed-capacity list, no allocation.

/// The rule a value breaks (the names are those of battgen's Python validators).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// NaN where the field has no NaN "unknown" value.
    Nan,
    /// Beyond what the type holds (a float that is not finite).
    TypeBounds,
    /// Outside the schema's range.
    Range,
    /// Not one of the field's enum values.
    Enum,
    /// Sets bits its bitmask does not define.
    Bitmask,
    /// A variable-length array longer than its capacity.
    Length,
    /// Breaks the cross-field rule of this id (schemas/rules/).
    CrossField(&'static str),
    /// A DroneCAN union's tag names none of its fields.
    Union,
}

impl Rule {
    /// The rule's name as battgen's Python validators spell it (`cross-field` without its id:
    /// [`Rule::rule_id`] gives that, and `Display` writes both).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Rule::Nan => "nan",
            Rule::TypeBounds => "type-bounds",
            Rule::Range => "range",
            Rule::Enum => "enum",
            Rule::Bitmask => "bitmask",
            Rule::Length => "length",
            Rule::CrossField(_) => "cross-field",
            Rule::Union => "union",
        }
    }

    /// The id of the cross-field rule broken (None for a rule of one value).
    #[must_use]
    pub const fn rule_id(self) -> Option<&'static str> {
        match self {
            Rule::CrossField(id) => Some(id),
            _ => None,
        }
    }
}

/// The rule as the Python validators spell a violation's `rule`: `range`, `cross-field:<id>`.
impl core::fmt::Display for Rule {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Rule::CrossField(id) => write!(f, "cross-field:{id}"),
            _ => f.write_str(self.name()),
        }
    }
}

/// One broken rule: the field (as the schema names it), the array position, the rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Problem {
    /// The field's name in the schema.
    pub field: &'static str,
    /// The element of an array field, None for a scalar.
    pub index: Option<usize>,
    /// What is wrong.
    pub rule: Rule,
}

const EMPTY: Problem = Problem {
    field: "",
    index: None,
    rule: Rule::Nan,
};

/// Up to `N` problems; a message's `validate` sizes `N` so that every problem fits, and a
/// smaller list counts those it had to drop in [`Problems::dropped`].
#[derive(Clone, Debug)]
pub struct Problems<const N: usize> {
    items: [Problem; N],
    len: usize,
    dropped: usize,
}

impl<const N: usize> Default for Problems<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Problems<N> {
    /// An empty list.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            items: [EMPTY; N],
            len: 0,
            dropped: 0,
        }
    }

    /// Record one problem (counted in `dropped` when the list is full).
    pub fn push(&mut self, field: &'static str, index: Option<usize>, rule: Rule) {
        if self.len < N {
            self.items[self.len] = Problem { field, index, rule };
            self.len += 1;
        } else {
            self.dropped += 1;
        }
    }

    /// The problems recorded, in the order of the message's fields.
    #[must_use]
    pub fn as_slice(&self) -> &[Problem] {
        &self.items[..self.len]
    }

    /// How many problems were recorded.
    #[must_use]
    pub const fn len(&self) -> usize {
        self.len
    }

    /// True when the message broke no rule.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        self.len == 0 && self.dropped == 0
    }

    /// Problems that did not fit.
    #[must_use]
    pub const fn dropped(&self) -> usize {
        self.dropped
    }
}

/// A message that checks itself against its schema.
pub trait Validate {
    /// Append every problem of `self` to `out`.
    fn validate_into<const N: usize>(&self, out: &mut Problems<N>);
}
