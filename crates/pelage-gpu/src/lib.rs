//! pelage-gpu: the wgpu renderer (shell fur, strand and point preview,
//! headless and windowed), with its WGSL in `src/shaders/`.
//!
//! Its own crate because wgpu is the heaviest dependency by far: the library
//! and its tests build without it. It is empty until the GPU-layer issue
//! (the renderer) lands; the foundation only reserves its place in the
//! workspace so the layout matches ARCHITECTURE.md from the start.
