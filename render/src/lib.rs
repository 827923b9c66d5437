//! Render (to be built by the render issue): the wgpu four-way flowed light-field
//! renderer (relighting pass, light-field re-binning through the squashed cylinder of
//! camera centres, four-way flowed morph, shadows and compositing, WGSL shaders in
//! `shaders/`) and its CPU reference of the same mathematics.
//! Conventions: [`frf_core::conventions`].
