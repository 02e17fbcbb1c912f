//! The atmosphere's air and transmittance table (src/planet/atmosphere.rs): the numbers the shaders read.

use riverplanet::planet::{air, atmosphere::Atmosphere};

fn appendix_a() -> Atmosphere {
    Atmosphere::new(1024.0, 0.4, 32.0).unwrap()
}

#[test]
fn straight_up_the_air_lets_through_what_its_optical_depth_says() {
    let a = appendix_a();
    let t = a.transmittance(a.bottom, 1.0, 4000);
    // Exponential air up to the top of the shell: depth = tau (1 - e^(-height / scale height)).
    let height = a.top - a.bottom;
    let mie =
        air::MIE_OPTICAL_DEPTH * air::MIE_EXTINCTION_RATIO * (1.0 - (-height / a.mie_height).exp());
    for (c, (t, tau)) in t.iter().zip(air::RAYLEIGH_OPTICAL_DEPTH).enumerate() {
        let depth = tau * (1.0 - (-height / a.rayleigh_height).exp()) + mie;
        let expected = (-depth).exp();
        assert!(
            (t - expected).abs() < 1e-5,
            "channel {c}: {t} instead of {expected}"
        );
    }
    // Blue is scattered most: the overhead sun is yellowish.
    assert!(t[2] < t[1] && t[1] < t[0]);
}

#[test]
fn no_light_comes_through_the_ground_and_the_horizon_is_dimmer_than_the_zenith() {
    let a = appendix_a();
    let r = a.bottom + 1.0;
    assert_eq!(a.transmittance(r, a.horizon_mu(r) - 0.01, 100), [0.0; 3]);
    let horizon = a.transmittance(r, a.horizon_mu(r) + 1e-4, 2000);
    let zenith = a.transmittance(r, 1.0, 2000);
    assert!(horizon[2] < 0.05 * zenith[2], "{horizon:?} vs {zenith:?}");
}

/// The table read as the shaders read it (bilinear between texel centres) gives the integral within 1 % at any
/// altitude and sun angle from 0.02 above the horizon (nearer the horizon, within about 2 %).
#[test]
fn the_table_answers_like_the_integral() {
    let a = appendix_a();
    let table = a.transmittance_table();
    let (w, h) = (table.width as f64, table.height as f64);
    let texel = |x: i64, y: i64| {
        let x = x.clamp(0, table.width as i64 - 1) as usize;
        let y = y.clamp(0, table.height as i64 - 1) as usize;
        table.texels[y * table.width as usize + x]
    };
    let mut worst: f64 = 0.0;
    for k in 0..40 {
        let r = a.bottom + (a.top - a.bottom) * (k as f64 / 40.0).powi(2);
        for m in 0..50 {
            let horizon = a.horizon_mu(r);
            let mu = horizon + 0.02 + (1.0 - horizon - 0.02) * m as f64 / 49.0;
            let [u, v] = a.table_uv(r, mu);
            let (x, y) = (u * w - 0.5, v * h - 0.5);
            let (x0, y0) = (x.floor(), y.floor());
            let (fx, fy) = (x - x0, y - y0);
            let (x0, y0) = (x0 as i64, y0 as i64);
            let exact = a.transmittance(r, mu, 2000);
            for (c, exact) in exact.iter().enumerate() {
                let lerp = |p: f64, q: f64, f: f64| p + (q - p) * f;
                let read = lerp(
                    lerp(texel(x0, y0)[c] as f64, texel(x0 + 1, y0)[c] as f64, fx),
                    lerp(
                        texel(x0, y0 + 1)[c] as f64,
                        texel(x0 + 1, y0 + 1)[c] as f64,
                        fx,
                    ),
                    fy,
                );
                worst = worst.max((read - exact).abs() / exact.max(1e-3));
            }
        }
    }
    assert!(worst < 0.01, "largest relative error {worst}");
}

#[test]
fn the_table_coordinates_invert() {
    let a = appendix_a();
    for (r, mu) in [(a.bottom, 0.3), (a.bottom + 5.0, -0.1), (a.top - 1.0, 0.9)] {
        let (r2, mu2) = a.table_r_mu(a.table_uv(r, mu));
        assert!(
            (r - r2).abs() < 1e-9 && (mu - mu2).abs() < 1e-9,
            "{r} {mu}: {r2} {mu2}"
        );
    }
}

#[test]
fn a_planet_without_air_has_no_atmosphere() {
    assert!(Atmosphere::new(1024.0, 0.4, 0.0).is_none());
}
