"""Animation scripts (``.anim``) run into trajectories: state-space controllers swapped in turn,
and motor programs, on a compiled figure; the state-space family."""
