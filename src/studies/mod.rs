//! Studies made of many runs: what accuracy costs in time ([`accuracy`]: the exact engine
//! against the approximate schemes and cheaper models on one scene), parameter sweeps and seed
//! ensembles on this machine's cores or a Slurm cluster ([`sweep`]), and what their SVG figures
//! share ([`figure`]: axes with readable ticks, markers, legends outside the plots).

pub mod accuracy;
pub mod figure;
pub mod sweep;
