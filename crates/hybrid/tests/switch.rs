//! The hysteresis rule (Eq. 8) on scripted boundary-measure sequences: entering the shell, leaving
//! it, no chatter inside the band, starting in the shell, and the single-threshold degenerate case.

use emg_hybrid::{HysteresisSwitch, Regime, SwitchConfig};

fn run(config: SwitchConfig, start: f64, measures: &[f64]) -> (Vec<Regime>, usize) {
    let mut switch = HysteresisSwitch::new(config).expect("valid thresholds");
    let mut regimes = vec![switch.start(start)];
    regimes.extend(measures.iter().map(|&m| switch.update(m)));
    (regimes, switch.switches())
}

use Regime::{Classical as C, Learned as L};

#[test]
fn enters_at_tau_enter_and_exits_below_tau_exit() {
    let config = SwitchConfig {
        tau_enter: 0.98,
        tau_exit: 0.94,
    };
    let (regimes, switches) = run(
        config,
        0.5,
        &[0.9, 0.97, 0.98, 0.99, 0.95, 0.94, 0.9399, 0.97, 0.98],
    );
    assert_eq!(regimes, vec![L, L, L, C, C, C, C, L, L, C]);
    assert_eq!(switches, 3);
}

#[test]
fn no_chatter_inside_the_band() {
    let config = SwitchConfig {
        tau_enter: 0.98,
        tau_exit: 0.94,
    };
    let oscillation: Vec<f64> = (0..50)
        .map(|k| if k % 2 == 0 { 0.979 } else { 0.941 })
        .collect();
    // From the interior, oscillating inside the band never enters the shell.
    let (regimes, switches) = run(config.clone(), 0.5, &oscillation);
    assert!(regimes.iter().all(|&r| r == L));
    assert_eq!(switches, 0);
    // Once in the shell, oscillating inside the band never leaves it.
    let mut measures = vec![0.985];
    measures.extend(&oscillation);
    let (regimes, switches) = run(config, 0.5, &measures);
    assert!(regimes[1..].iter().all(|&r| r == C));
    assert_eq!(switches, 1);
}

#[test]
fn a_seed_in_the_shell_starts_classical() {
    let config = SwitchConfig {
        tau_enter: 0.98,
        tau_exit: 0.94,
    };
    let (regimes, switches) = run(config.clone(), 0.99, &[0.97, 0.93]);
    assert_eq!(regimes, vec![C, C, L]);
    assert_eq!(switches, 1);
    let (regimes, _) = run(config, 0.979, &[0.979]);
    assert_eq!(regimes, vec![L, L]);
}

#[test]
fn a_single_threshold_switches_at_every_crossing() {
    let config = SwitchConfig {
        tau_enter: 0.95,
        tau_exit: 0.95,
    };
    let (regimes, switches) = run(config, 0.5, &[0.96, 0.94, 0.96, 0.94]);
    assert_eq!(regimes, vec![L, C, L, C, L]);
    assert_eq!(switches, 4);
}

#[test]
fn inverted_thresholds_are_rejected_with_both_values() {
    let error = HysteresisSwitch::new(SwitchConfig {
        tau_enter: 0.9,
        tau_exit: 0.95,
    })
    .unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains("tau_enter = 0.9") && message.contains("tau_exit = 0.95"),
        "{message}"
    );
    assert!(
        HysteresisSwitch::new(SwitchConfig {
            tau_enter: f64::NAN,
            tau_exit: 0.9
        })
        .is_err()
    );
}
