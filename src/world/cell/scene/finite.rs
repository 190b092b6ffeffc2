//! The numbers of a cell (sizes, positions, angles, masses, the robot's reach): each is
//! read as a finite number of modest size, so geometry never meets an infinity or a NaN
//! (TOML allows `nan` and `inf`, and a number beyond `f32` reads as infinite). A number
//! that is not is refused where it is written.

use serde::{Deserialize, Deserializer};

/// Larger numbers are refused: metres, kilograms and degrees of a tabletop cell are far
/// smaller, and sums of such numbers stay exact enough in `f32`.
pub const MAX_MAGNITUDE: f32 = 10_000.0;

/// Values made of `f32`s.
pub trait Numbers {
    fn all_modest(&self) -> bool;
}

impl Numbers for f32 {
    fn all_modest(&self) -> bool {
        self.is_finite() && self.abs() <= MAX_MAGNITUDE
    }
}

impl<const N: usize> Numbers for [f32; N] {
    fn all_modest(&self) -> bool {
        self.iter().all(Numbers::all_modest)
    }
}

impl<T: Numbers> Numbers for Vec<T> {
    fn all_modest(&self) -> bool {
        self.iter().all(Numbers::all_modest)
    }
}

impl<T: Numbers> Numbers for Option<T> {
    fn all_modest(&self) -> bool {
        self.as_ref().is_none_or(Numbers::all_modest)
    }
}

/// `deserialize_with` for the numbers of a cell.
pub fn modest<'de, D, T>(d: D) -> Result<T, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de> + Numbers,
{
    let value = T::deserialize(d)?;
    if value.all_modest() {
        Ok(value)
    } else {
        Err(serde::de::Error::custom(format!(
            "expected finite numbers of at most {MAX_MAGNITUDE} in size"
        )))
    }
}
