//! The house: layers as folders, imports flowing down, no import circles.

mod layers;
