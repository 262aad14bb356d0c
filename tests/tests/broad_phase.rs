//! `lagrange_world::BroadPhase` against the brute-force test of every pair: 50 random scenes of
//! up to 60 proxies (boxes anywhere in a 10 m square, static, asleep, bodies of several
//! proxies, random groups and masks) give exactly the pairs that overlap and may touch, in
//! key order, whatever the order the proxies were added in; bad proxies and full outputs are
//! refused by name. Both precisions.

use lagrange_core::{Error, Real};
use lagrange_tests::{for_f32_and_f64, Rng};
use lagrange_world::{BroadPhase, Proxy};

/// The pairs brute force keeps: boxes overlapping on both axes, not both resting (static or
/// asleep), not one body, each one's group in the other's mask.
fn brute<T: Real>(proxies: &[Proxy<T>]) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for (i, a) in proxies.iter().enumerate() {
        for b in &proxies[i + 1..] {
            let overlap =
                (0..2).all(|k| a.bounds.0[k] <= b.bounds.1[k] && b.bounds.0[k] <= a.bounds.1[k]);
            let resting = (a.fixed || a.asleep) && (b.fixed || b.asleep);
            let groups = (a.group & b.mask) != 0 && (b.group & a.mask) != 0;
            if overlap && !resting && a.body != b.body && groups {
                out.push((a.key.min(b.key), a.key.max(b.key)));
            }
        }
    }
    out.sort_unstable();
    out
}

fn random_proxy<T: Real>(rng: &mut Rng, key: u32) -> Proxy<T> {
    let (x, y): (f64, f64) = (rng.uniform(0.0, 10.0), rng.uniform(0.0, 10.0));
    let (w, h): (f64, f64) = (rng.uniform(0.05, 2.0), rng.uniform(0.05, 2.0));
    Proxy {
        bounds: (
            [T::from_f64(x), T::from_f64(y)],
            [T::from_f64(x + w), T::from_f64(y + h)],
        ),
        body: (rng.unit() * 20.0) as u32,
        key,
        group: 1 << ((rng.unit() * 3.0) as u32),
        mask: if rng.unit() < 0.2 { 0b011 } else { u32::MAX },
        fixed: rng.unit() < 0.2,
        asleep: rng.unit() < 0.2,
    }
}

fn matches_brute_force<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(341);
    let mut pairs_seen = 0;
    for _ in 0..50 {
        let n = 1 + (rng.unit() * 60.0) as usize;
        let proxies: Vec<Proxy<T>> = (0..n)
            .map(|k| random_proxy(&mut rng, 1000 - k as u32))
            .collect();
        let expected = brute(&proxies);
        pairs_seen += expected.len();
        for reversed in [false, true] {
            let mut broad = BroadPhase::<T, 64>::new();
            let order: Vec<&Proxy<T>> = if reversed {
                proxies.iter().rev().collect()
            } else {
                proxies.iter().collect()
            };
            for p in order {
                broad.add(*p)?;
            }
            let mut out = heapless::Vec::<(u32, u32), 2048>::new();
            broad.pairs(&mut out)?;
            assert_eq!(out.as_slice(), expected.as_slice());
        }
    }
    println!("{pairs_seen} pairs in 50 scenes");
    assert!(pairs_seen > 100);
    Ok(())
}

fn bad_input_is_refused<T: Real>() -> Result<(), Error> {
    let named = |r: Result<(), Error>, name: &str| {
        assert!(
            matches!(r, Err(Error::InvalidParameter { name: n, .. }) if n == name),
            "{name}: {r:?}"
        );
    };
    let mut rng = Rng::new(342);
    let good = random_proxy::<T>(&mut rng, 1);
    let mut broad = BroadPhase::<T, 2>::new();
    broad.add(good)?;
    named(broad.add(good), "proxy");
    let upside_down = Proxy {
        bounds: (good.bounds.1, good.bounds.0),
        key: 2,
        ..good
    };
    named(broad.add(upside_down), "proxy");
    let nan = Proxy {
        bounds: ([T::from_f64(f64::NAN), T::zero()], [T::one(); 2]),
        key: 3,
        ..good
    };
    named(broad.add(nan), "proxy");
    broad.add(Proxy {
        key: 4,
        body: good.body + 1,
        fixed: false,
        asleep: false,
        group: 1,
        mask: 1,
        ..good
    })?;
    named(broad.add(Proxy { key: 5, ..good }), "capacity");
    assert_eq!(broad.proxies().len(), 2);
    // Two proxies of two bodies on the same box: one pair, which an output of none cannot hold.
    let mut none = heapless::Vec::<(u32, u32), 0>::new();
    let both = Proxy {
        group: 1,
        mask: 1,
        fixed: false,
        asleep: false,
        ..good
    };
    let mut broad = BroadPhase::<T, 2>::new();
    broad.add(both)?;
    broad.add(Proxy {
        key: 9,
        body: good.body + 1,
        ..both
    })?;
    named(broad.pairs(&mut none), "capacity");
    broad.clear();
    assert!(broad.proxies().is_empty());
    Ok(())
}

for_f32_and_f64!(matches_brute_force, bad_input_is_refused);
