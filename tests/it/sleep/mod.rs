//! Sleeping islands: falling asleep, waking on contact and on structural change.

mod islands;
mod joints_join_islands;
mod structural_change_wakes;
mod wake_in_the_step_of_impact;
