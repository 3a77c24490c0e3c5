#!/usr/bin/python3
"""How far the IMU alone errs along a blind passage (lidar degenerate along it, camera seeing nothing move), from its
own noise only: a perfect entry state (position, velocity, bias exact), then dead reckoning along the passage.

The simulated IMU of src/sim/imu_model.hpp: accelerometer white noise sigma_a [m/s^2/sqrt(Hz)] and bias random walk
sigma_b [m/s^3/sqrt(Hz)] at 200 Hz. Double integration gives the variance sigma_a^2 T^3 / 3 + sigma_b^2 T^5 / 20 of
the forward position error after T seconds; a Monte Carlo of the same discrete model checks it.

Usage: imu_bridge_noise.py [--seconds 10 25 35] [--runs 4000] [--acc-noise 2e-3] [--acc-bias-walk 3e-4]
"""
import argparse

import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, nargs="+", default=[10, 25, 35])
    ap.add_argument("--runs", type=int, default=4000)
    ap.add_argument("--rate", type=float, default=200.0)
    ap.add_argument("--acc-noise", type=float, default=2.0e-3)
    ap.add_argument("--acc-bias-walk", type=float, default=3.0e-4)
    a = ap.parse_args()
    rng = np.random.default_rng(1)
    dt = 1.0 / a.rate
    print("passage [s] | forward error 1 sigma, Monte Carlo / analytic [m] | median |error| [m] | 90th percentile [m]")
    for T in a.seconds:
        n = int(round(T / dt))
        white = rng.standard_normal((a.runs, n)) * a.acc_noise / np.sqrt(dt)
        bias = np.cumsum(rng.standard_normal((a.runs, n)) * a.acc_bias_walk * np.sqrt(dt), axis=1)
        position = np.cumsum(np.cumsum(white + bias, axis=1) * dt, axis=1) * dt
        e = position[:, -1]
        analytic = np.sqrt(a.acc_noise**2 * T**3 / 3 + a.acc_bias_walk**2 * T**5 / 20)
        print(f"{T:g} | {e.std():.3f} / {analytic:.3f} | {np.median(np.abs(e)):.3f} | "
              f"{np.percentile(np.abs(e), 90):.3f}")


if __name__ == "__main__":
    main()
