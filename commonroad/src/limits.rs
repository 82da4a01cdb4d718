//! The documented limits of the reader (listed by `merge_sim limits`). They bound the work and
//! memory a file can ask for; CommonRoad's benchmark files stay far below them (the US-101 test
//! file: 12 lanelets, 22 obstacles, 80 states per obstacle at most).

/// Largest file read (bytes): 64 MiB.
pub const MAX_FILE_BYTES: u64 = 64 << 20;
/// Most lanelets in one file.
pub const MAX_LANELETS: usize = 2_000;
/// Most obstacles (dynamic and static together) in one file.
pub const MAX_OBSTACLES: usize = 5_000;
/// Most trajectory states of one obstacle.
pub const MAX_STATES_PER_OBSTACLE: usize = 100_000;
