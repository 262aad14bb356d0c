//! The standard problems P1-P5 of `shared/BENCH_PROBLEMS.md` and their registry.

mod p1_pendulum;
mod p2_double;
pub mod p3_chain;
pub mod p4_kepler;
mod p5_elastic;

use super::problem::ProblemVisitor;

/// The problems table: one line per problem. Adding a problem is one entry here (and its file).
pub fn for_each(v: &mut impl ProblemVisitor) {
    v.visit(&p1_pendulum::OriginPendulum);
    v.visit(&p2_double::ChaoticDouble);
    v.visit(&p3_chain::CHAIN_5);
    v.visit(&p3_chain::CHAIN_20);
    v.visit(&p4_kepler::KeplerOrbit);
    v.visit(&p5_elastic::StiffElastic);
}
