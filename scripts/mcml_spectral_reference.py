#!/usr/bin/env python3
"""Independent spectral reference for rtbake's Monte Carlo skin profiles: the original MCML 1.2.2 run per wavelength.

For each skin (melanin fraction Cm, dermal hemoglobin fraction Chd) and each Henyey-Greenstein anisotropy g, this
script
  1. asks rtbake for the two-layer coefficients per wavelength (`cargo run --example skin_coefficients -- CM CHD`,
     i.e. `SkinPhysiology::coefficients_at`: sigma_a and sigma_s' of epidermis and dermis in mm^-1, thicknesses,
     refractive indices), 380-780 nm every 10 nm;
  2. writes one MCML input file with, per wavelength, BATCHES independent runs of PHOTONS/BATCHES photons:
     air (n = 1) / epidermis / dermis / medium below, mua = 10 sigma_a cm^-1, mus = 10 sigma_s' / (1 - g) cm^-1,
     thicknesses in cm;
  3. runs MCML 1.2.2 (Wang, Jacques & Zheng 1995; github.com/lhvwang/MCML) on it and reads each run's total
     diffuse reflectance Rd and specular reflectance Rsp;
  4. normalises per unit flux entering the surface, Rd / (1 - Rsp) (rtbake's and the diffusion models'
     normalisation), and projects the spectrum to linear sRGB with its own implementation of the projection:
     w_c(lambda) = s_c(lambda) / sum_lambda s_c(lambda), s = M_sRGB . (D65 x CIE 1931 2-degree CMF) sampled at
     380, 390, ..., 780 nm (the 1 nm tables in ../shared/data or --data-dir; M = IEC 61966-2-1 XYZ -> linear sRGB),
     so a flat reflectance of 1 gives 1 in each channel;
  5. takes the channel value as the mean over the batches and its standard error as std(batches) / sqrt(BATCHES).

MCML 1.2.2 seeds its generator once per process with -(time(NULL) mod 2^15); each (skin, g) is one process, started
at least a second after the previous one (the launch second is recorded: it determines the seed up to a tick).

Usage: scripts/mcml_spectral_reference.py --mcml /path/to/mcml --out tests/fixtures/mcml_spectral_skin.json
       [--photons 40000] [--batches 4] [--skins 0.07:0.04,0.3:0.08] [--g 0,0.8] [--data-dir ../shared/data]
Needs numpy and a built rtbake checkout (run from the repository root).
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

SRGB_FROM_XYZ = np.array([[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]])
STEP_NM = 10


def read_table(path):
    rows = [line.strip().split(",") for line in open(path) if line.strip() and not line.startswith("#")]
    header, body = rows[0], rows[1:]
    data = np.array([[float(x) for x in r] for r in body])
    return header, data


def projection_weights(data_dir):
    _, cmf = read_table(os.path.join(data_dir, "cie1931_2deg_cmf_380_780_1nm.csv"))
    _, d65 = read_table(os.path.join(data_dir, "cie_d65_380_780_1nm.csv"))
    lambdas = np.arange(380, 781, STEP_NM)
    idx_c = [int(np.where(cmf[:, 0] == l)[0][0]) for l in lambdas]
    idx_s = [int(np.where(d65[:, 0] == l)[0][0]) for l in lambdas]
    xyz = cmf[idx_c, 1:4] * d65[idx_s, 1:2]  # S(lambda) (xbar, ybar, zbar)
    rgb = xyz @ SRGB_FROM_XYZ.T  # per wavelength, linear-sRGB sensitivity
    return lambdas, rgb / rgb.sum(axis=0)  # per channel, flat 1 -> 1


def coefficients(cm, chd):
    out = subprocess.run(
        ["cargo", "run", "--quiet", "--example", "skin_coefficients", "--", str(cm), str(chd), str(STEP_NM)],
        check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def mci_text(coef, g, photons_per_run, batches, prefix):
    p = coef["physiology"]
    runs = []
    for c in coef["coefficients"]:
        for b in range(batches):
            epi, derm = c["epidermis"], c["dermis"]
            runs.append(f"""{prefix}_{int(c['lambda_nm'])}_{b}.mco A
{photons_per_run}
0.01 0.01
10 10 1
2
1.0
{p['eta_epidermis']} {10 * epi['sigma_a_per_mm']!r} {10 * epi['sigma_s_prime_per_mm'] / (1 - g)!r} {g} {p['epidermis_thickness_mm'] / 10!r}
{p['eta_dermis']} {10 * derm['sigma_a_per_mm']!r} {10 * derm['sigma_s_prime_per_mm'] / (1 - g)!r} {g} {p['dermis_thickness_mm'] / 10!r}
{p['eta_below_dermis']}
""")
    return f"1.0\n{len(runs)}\n\n" + "\n".join(runs)


def read_mco(path):
    text = open(path).read()
    rsp = float(re.search(r"^\s*(\S+)\s+#Specular reflectance", text, re.M).group(1))
    rd = float(re.search(r"^\s*(\S+)\s+#Diffuse reflectance", text, re.M).group(1))
    return rd, rsp


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mcml", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--photons", type=int, default=40000, help="photons per wavelength (all batches together)")
    ap.add_argument("--batches", type=int, default=4)
    ap.add_argument("--skins", default="0.07:0.04,0.3:0.08")
    ap.add_argument("--g", default="0,0.8")
    ap.add_argument("--data-dir", default=os.path.join("..", "shared", "data"))
    a = ap.parse_args()
    lambdas, w = projection_weights(a.data_dir)
    skins = [tuple(float(x) for x in s.split(":")) for s in a.skins.split(",")]
    gs = [float(x) for x in a.g.split(",")]
    per_run = a.photons // a.batches
    results = []
    for cm, chd in skins:
        coef = coefficients(cm, chd)
        assert [c["lambda_nm"] for c in coef["coefficients"]] == list(map(float, lambdas))
        for g in gs:
            with tempfile.TemporaryDirectory(prefix="mcml-ref-") as tmp:
                with open(os.path.join(tmp, "in.mci"), "w") as f:
                    f.write(mci_text(coef, g, per_run, a.batches, "run"))
                time.sleep(1.1)  # a fresh time(NULL) second, so a fresh seed
                launch = int(time.time())
                t0 = time.time()
                subprocess.run([a.mcml, "in.mci"], cwd=tmp, check=True, capture_output=True)
                seconds = time.time() - t0
                rd = np.zeros((len(lambdas), a.batches))
                rsp = None
                for i, l in enumerate(lambdas):
                    for b in range(a.batches):
                        rd[i, b], rsp = read_mco(os.path.join(tmp, f"run_{l}_{b}.mco"))
            entering = rd / (1.0 - rsp)
            per_batch = w.T @ entering  # (3, batches)
            total = per_batch.mean(axis=1)
            se = per_batch.std(axis=1, ddof=1) / np.sqrt(a.batches)
            results.append({
                "melanin_fraction": cm, "hemoglobin_fraction": chd, "g": g,
                "total_R": total.tolist(), "total_R_se": se.tolist(),
                "specular_reflectance": rsp,
                "mcml_launch_unix_second": launch,
                "mcml_seed": f"-({launch} mod 32768) = {-(launch % 32768)} (MCML 1.2.2 time seed; +-1 if the second ticked)",
                "mcml_seconds": round(seconds, 1),
                "rd_per_wavelength_entering": entering.mean(axis=1).tolist(),
            })
            print(f"Cm {cm} Chd {chd} g {g}: R {total} SE {se} ({seconds:.0f} s)", file=sys.stderr)
    fixture = {
        "what": "total diffuse reflectance per linear-sRGB channel of rtbake's physiological two-layer skin, "
                "per unit flux entering the surface, from the original MCML run per wavelength and projected "
                "independently (D65, CIE 1931 2 degree, IEC 61966-2-1 matrix, 380-780 nm every 10 nm, per channel "
                "normalised so a flat reflectance of 1 gives 1)",
        "mcml": "MCML 1.2.2 (Wang, Jacques & Zheng 1995; github.com/lhvwang/MCML, V1/mcR5unix), gcc -O3 -march=native, "
                "statistical (not split) boundary reflection, Russian roulette as shipped",
        "photons_per_wavelength": per_run * a.batches,
        "batches_per_wavelength": a.batches,
        "standard_error": "std over the batches (ddof 1) / sqrt(batches), of the projected channel value",
        "layers": "air n=1 / epidermis / dermis / below; mua = 10 sigma_a cm^-1, mus = 10 sigma_s' / (1 - g) cm^-1, "
                  "d in cm; coefficients from `cargo run --example skin_coefficients -- CM CHD 10` (rtbake's "
                  "SkinPhysiology::coefficients_at, default physiology)",
        "grid": "dz = dr = 0.01 cm, nz = nr = 10, na = 1 (only the total Rd is used; MCML folds r beyond the grid "
                "into the last bin, so the total is complete)",
        "wavelengths_nm": lambdas.tolist(),
        "command": "python3 scripts/mcml_spectral_reference.py " + " ".join(sys.argv[1:]),
        "script": "scripts/mcml_spectral_reference.py",
        "results": results,
    }
    tmp_out = a.out + ".tmp"
    with open(tmp_out, "w") as f:
        json.dump(fixture, f, indent=1)
        f.write("\n")
    os.replace(tmp_out, a.out)


if __name__ == "__main__":
    main()
