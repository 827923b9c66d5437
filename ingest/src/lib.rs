//! Ingest (to be built by the ingest issue): turns a capture (see [`frf_core::capture`])
//! into a flowed reflectance field: mattes from track and matte frames, lighting-basis
//! registration by optical flow, inter-view flow for every grid neighbour, and the
//! write-out through the reflectance container, with a report of each step's error
//! against the virtual light stage's ground truth. Conventions: [`frf_core::conventions`].
