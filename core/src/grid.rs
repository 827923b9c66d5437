//! The grid of views ([`crate::conventions`]): view `(u, v)` with `u` the cycle
//! (horizontal, wrapping around a turntable) and `v` the camera (vertical), and the
//! neighbour relation that flows are stored for.

use serde::{Deserialize, Serialize};

/// A neighbour in the grid of views.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Neighbour {
    /// `(u + 1, v)`.
    Right,
    /// `(u - 1, v)`.
    Left,
    /// `(u, v + 1)`.
    Up,
    /// `(u, v - 1)`.
    Down,
}

impl Neighbour {
    /// All four, in storage order.
    pub const ALL: [Neighbour; 4] = [
        Neighbour::Right,
        Neighbour::Left,
        Neighbour::Up,
        Neighbour::Down,
    ];

    /// The name used in file names and messages.
    pub fn name(self) -> &'static str {
        match self {
            Neighbour::Right => "right",
            Neighbour::Left => "left",
            Neighbour::Up => "up",
            Neighbour::Down => "down",
        }
    }

    /// Index in [`Neighbour::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The opposite direction (the flow back).
    pub fn opposite(self) -> Neighbour {
        match self {
            Neighbour::Right => Neighbour::Left,
            Neighbour::Left => Neighbour::Right,
            Neighbour::Up => Neighbour::Down,
            Neighbour::Down => Neighbour::Up,
        }
    }

    /// The neighbour of view `(u, v)` in a grid of `columns x rows`, if it exists:
    /// columns wrap around when `wraps` (a full turntable circle), rows never do.
    pub fn of(
        self,
        u: usize,
        v: usize,
        columns: usize,
        rows: usize,
        wraps: bool,
    ) -> Option<(usize, usize)> {
        match self {
            Neighbour::Right if u + 1 < columns => Some((u + 1, v)),
            Neighbour::Right => (wraps && columns > 1).then_some((0, v)),
            Neighbour::Left if u > 0 => Some((u - 1, v)),
            Neighbour::Left => (wraps && columns > 1).then_some((columns - 1, v)),
            Neighbour::Up => (v + 1 < rows).then_some((u, v + 1)),
            Neighbour::Down => v.checked_sub(1).map(|v| (u, v)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbours_wrap_in_u_only() {
        assert_eq!(Neighbour::Right.of(35, 1, 36, 3, true), Some((0, 1)));
        assert_eq!(Neighbour::Left.of(0, 1, 36, 3, true), Some((35, 1)));
        assert_eq!(Neighbour::Left.of(0, 1, 36, 3, false), None);
        assert_eq!(Neighbour::Up.of(4, 2, 36, 3, true), None);
        assert_eq!(Neighbour::Down.of(4, 0, 36, 3, true), None);
        assert_eq!(Neighbour::Down.of(4, 2, 36, 3, true), Some((4, 1)));
        // Top and bottom rows have 3 neighbours, the middle row 4.
        for (v, n) in [(0, 3), (1, 4), (2, 3)] {
            let count = Neighbour::ALL
                .iter()
                .filter(|d| d.of(7, v, 36, 3, true).is_some())
                .count();
            assert_eq!(count, n);
        }
        for d in Neighbour::ALL {
            assert_eq!(d.opposite().opposite(), d);
        }
    }
}
