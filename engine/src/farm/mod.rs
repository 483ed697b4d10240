//! Rendering across machines. A frame's samples split into disjoint
//! [`partition`]s that separate machines render into [`partial`] EXR files
//! (the film's weighted sums, with what rendered them in the header);
//! [`merge`] adds the partial films back into one frame. [`slurm`] writes
//! (and submits) the job scripts that spread a sequence's frames, or a
//! frame's partitions, over a Slurm cluster, and [`status`] tells which
//! frames of a sequence are done.

pub mod merge;
pub mod partial;
pub mod partition;
pub mod slurm;
pub mod status;
