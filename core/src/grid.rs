//! The grid of views ([`crate::conventions`]): view `(u, v)` with `u` the cycle
//! (horizontal, wrapping around a turntable) and `v` the camera (vertical), and the
//! neighbour relation that flows are stored for; and the step in time from a pose to the
//! next or previous captured one ([`PoseStep`]), which pose-to-pose flows are stored for.

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

/// A step in time from a pose to the next or the previous captured one, in the same view.
///
/// The views of one column `u` of a pose are one walk cycle, and consecutive poses are
/// consecutive instants of it; past the end of the cycle the walk goes on in the next
/// cycle, which the turntable has turned by one column: so the step from the last
/// captured pose to the first goes to column `u + 1` (and back from the first to the
/// last, to `u − 1`), where the same camera films the next instant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PoseStep {
    /// To the next captured pose.
    Next,
    /// To the previous captured pose.
    Prev,
}

impl PoseStep {
    /// Both, in storage order.
    pub const ALL: [PoseStep; 2] = [PoseStep::Next, PoseStep::Prev];

    /// The name used in messages.
    pub fn name(self) -> &'static str {
        match self {
            PoseStep::Next => "to the next pose",
            PoseStep::Prev => "to the previous pose",
        }
    }

    /// Index in [`PoseStep::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The opposite step (the flow back).
    pub fn opposite(self) -> PoseStep {
        match self {
            PoseStep::Next => PoseStep::Prev,
            PoseStep::Prev => PoseStep::Next,
        }
    }

    /// The pose this step leads to from `pose` among `poses` (sorted), whatever the
    /// column: the next (previous) of them, past the last (first) the first (last);
    /// `None` with fewer than two poses or when `pose` is not among them.
    pub fn target(self, pose: u32, poses: &[u32]) -> Option<u32> {
        let n = poses.len();
        if n < 2 {
            return None;
        }
        let i = poses.iter().position(|&p| p == pose)?;
        Some(match self {
            PoseStep::Next => poses[(i + 1) % n],
            PoseStep::Prev => poses[(i + n - 1) % n],
        })
    }

    /// The pose and column this step leads to from `pose` in column `u`, among the
    /// captured `poses` (sorted) of a grid of `columns` (wrapping when `wraps`): `None`
    /// with fewer than two poses, or when the column it needs does not exist.
    pub fn of(
        self,
        pose: u32,
        u: usize,
        poses: &[u32],
        columns: usize,
        wraps: bool,
    ) -> Option<(u32, usize)> {
        let to = self.target(pose, poses)?;
        let i = poses.iter().position(|&p| p == pose)?;
        let column = match self {
            PoseStep::Next if i + 1 < poses.len() => Some(u),
            PoseStep::Next => Neighbour::Right.of(u, 0, columns, 1, wraps).map(|c| c.0),
            PoseStep::Prev if i > 0 => Some(u),
            PoseStep::Prev => Neighbour::Left.of(u, 0, columns, 1, wraps).map(|c| c.0),
        };
        column.map(|c| (to, c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_steps_go_on_into_the_next_cycle_one_column_on() {
        let poses = [0, 3, 6];
        assert_eq!(PoseStep::Next.of(3, 5, &poses, 36, true), Some((6, 5)));
        assert_eq!(PoseStep::Prev.of(3, 5, &poses, 36, true), Some((0, 5)));
        assert_eq!(PoseStep::Next.of(6, 35, &poses, 36, true), Some((0, 0)));
        assert_eq!(PoseStep::Prev.of(0, 0, &poses, 36, true), Some((6, 35)));
        assert_eq!(PoseStep::Next.of(6, 35, &poses, 36, false), None);
        assert_eq!(PoseStep::Next.of(0, 0, &[0], 36, true), None);
        assert_eq!(PoseStep::Next.of(1, 0, &poses, 36, true), None);
        for step in PoseStep::ALL {
            for (pose, u) in [(0, 0), (3, 7), (6, 35)] {
                let (p, c) = step.of(pose, u, &poses, 36, true).unwrap();
                assert_eq!(step.opposite().of(p, c, &poses, 36, true), Some((pose, u)));
            }
        }
    }

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
