//! mergesim
