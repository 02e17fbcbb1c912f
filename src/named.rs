//! Closed sets of values that people name in words: on the command line (its own module turns these names into
//! its parsers, so that no library type depends on the argument parser) and in reports.

/// A value among a few, each with a name.
pub trait Named: Sized + Copy + PartialEq + 'static {
    /// Every value and its name.
    const ALL: &'static [(&'static str, Self)];

    /// The value called `text`.
    fn from_name(text: &str) -> Option<Self> {
        Self::ALL.iter().find(|(n, _)| *n == text).map(|(_, v)| *v)
    }

    /// This value's name.
    fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, v)| *v == self)
            .map_or("", |(n, _)| n)
    }
}

#[cfg(test)]
mod tests {
    use super::Named;
    use crate::{
        config::{LodRule, RiverModel},
        kernel::gpu::autotune::KernelChoice,
        render::{presets::Preset, ViewMode, WaterMode},
    };

    /// Every name reads back as its value and every value has one name.
    fn round_trip<T: Named + std::fmt::Debug>() {
        for (name, value) in T::ALL {
            assert_eq!(T::from_name(name), Some(*value), "{name}");
            assert_eq!(value.name(), *name);
        }
        assert_eq!(T::from_name("nothing"), None);
    }

    #[test]
    fn every_named_value_reads_back() {
        round_trip::<WaterMode>();
        round_trip::<ViewMode>();
        round_trip::<KernelChoice>();
        round_trip::<Preset>();
        round_trip::<LodRule>();
        round_trip::<RiverModel>();
    }
}
