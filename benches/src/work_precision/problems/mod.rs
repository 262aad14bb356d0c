//! The standard problems P1-P5 of `shared/BENCH_PROBLEMS.md` (with P3 at N = 10 and 40 too),
//! the N-body problems P6, and their registry.

mod p1_pendulum;
mod p2_double;
pub mod p3_chain;
pub mod p4_kepler;
mod p5_elastic;
pub mod p6_nbody;

use super::problem::ProblemVisitor;

/// The problems table: one line per problem. Adding a problem is one entry here (and its file).
pub fn for_each(v: &mut impl ProblemVisitor) {
    v.visit(&p1_pendulum::OriginPendulum);
    v.visit(&p2_double::ChaoticDouble);
    v.visit(&p3_chain::CHAIN_5);
    v.visit(&p3_chain::CHAIN_10);
    v.visit(&p3_chain::CHAIN_20);
    v.visit(&p3_chain::CHAIN_40);
    v.visit(&p4_kepler::KeplerOrbit);
    v.visit(&p5_elastic::StiffElastic);
    v.visit(&p6_nbody::Pleiades);
    v.visit(&p6_nbody::StarAndPlanets);
}
