//! Rendering across machines. A frame's samples split into disjoint
//! [`partition`]s that separate machines render into [`partial`] EXR files
//! (the film's weighted sums, with what rendered them in the header);
//! [`merge`] adds the partial films back into one frame. [`slurm`] writes
//! (and submits) the job scripts that spread a sequence's frames, or a
//! frame's partitions, over a Slurm cluster, and [`status`] tells which
//! frames of a sequence are done. [`resume`] keeps a progressive render's
//! state in the same partial format, so an interrupted render continues
//! where it stopped.

pub mod merge;
pub mod partial;
pub mod partition;
pub mod resume;
pub mod slurm;
pub mod status;
