"""``labbrdf psd`` and ``labbrdf.psd()``: end to end on real and written maps, error paths."""

from __future__ import annotations

import json

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError
from labbrdf.adapters.topography import HeightMap
from labbrdf.cli import main

GEOM = ["--pixel-size", "100nm", "--unit", "nm"]


@pytest.fixture
def txt_maps(tmp_path, synth):
    """A written K-correlation map, a map too small, a map and a profile with a gap."""
    z = synth.surface("k-correlation", (2e-28, 3e-6, 2.4), 64, 1e-7, seed=1) * 1e9  # nm
    ok = tmp_path / "ok.txt"
    np.savetxt(ok, z)
    small = tmp_path / "small.txt"
    np.savetxt(small, z[:10, :40])
    gaps = tmp_path / "gaps.txt"
    zg = z.copy()
    zg[3, 4] = np.nan
    np.savetxt(gaps, zg)
    return {"ok": ok, "small": small, "gaps": gaps}


def test_cli_writes_csv_png_and_json(txt_maps, tmp_path, capsys):
    csv, png = tmp_path / "psd.csv", tmp_path / "psd.png"
    args = ["psd", str(txt_maps["ok"]), *GEOM, "--fit", "k-correlation", "--json"]
    assert main([*args, "-o", str(csv), "--png", str(png)]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["kind"] == "2d" and d["unit"] == "m^4"
    assert d["maps"][0]["band_per_m"] == pytest.approx([1 / 6.4e-6, 5e6], rel=1e-12, abs=0)
    assert set(d["fit"]["values"]) == {"A", "B", "C"}
    assert csv.read_text().splitlines()[0] == "source,kind,f_per_m,psd,u,n,unit,model"
    assert png.read_bytes()[:4] == b"\x89PNG"
    # the CSV is not overwritten without --overwrite (exit 2, nothing changed)
    before = csv.read_bytes()
    assert main(["psd", str(txt_maps["ok"]), *GEOM, "-o", str(csv)]) == 2
    assert csv.read_bytes() == before
    assert "exists" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("which", "extra", "message"),
    [
        ("small", [], "too small for a PSD"),
        ("gaps", [], "1 undefined height points"),
        ("gaps", ["--kind", "1d"], "1 undefined height points"),
        ("ok", ["--unit", "furlong"], "unit 'furlong' unknown"),
        ("ok", ["--fit-band", "1e6"], "F_MIN:F_MAX"),
        ("ok", ["--fit-band", "1e5:1e6"], "--fit-band needs --fit"),
    ],
)
def test_cli_bad_input_exits_2_naming_the_file(txt_maps, capsys, which, extra, message):
    assert main(["psd", str(txt_maps[which]), *GEOM, *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    if "fit-band" not in message and "F_MIN" not in message:
        assert str(txt_maps[which]) in err
    assert len(err.strip().splitlines()) == 1


def test_python_entry_and_presentation(synth, tmp_path):
    z = synth.surface("exponential", (1e-9, 1e-6), 64, 1e-7, seed=2)
    coarse = synth.surface("exponential", (1e-9, 1e-6), 64, 4e-7, seed=3)
    maps = [
        HeightMap(z, (1e-7, 1e-7), "fine", "h"),
        HeightMap(coarse, (4e-7, 4e-7), "coarse", "h"),
    ]
    res = labbrdf.psd(maps, fit="exponential")
    assert res.kind == "2d" and len(res.spectra) == 2 and len(res.overlaps) == 1
    assert res.composite.band == (res.spectra[1].band[0], res.spectra[0].band[1])
    assert "exponential fit" in str(res) and "sigma" in str(res)
    html = res._repr_html_()
    assert "Surface PSD" in html and "fine" in html and "corr_length" in html
    frame = res.to_frame()
    assert set(frame["source"]) == {"fine", "coarse", "composite"}
    assert np.all(np.isfinite(frame["model"]))
    res.to_csv(tmp_path / "x.csv")
    assert (tmp_path / "x.csv").read_text().count("\n") == len(frame) + 1
    import matplotlib

    matplotlib.use("Agg")
    fig = res.plot()
    ax = fig.axes[0]
    assert ax.get_xscale() == "log" and "[1/m]" in ax.get_xlabel() and "m$^4$" in ax.get_ylabel()


def test_a_profile_refuses_the_2d_psd_naming_the_file(synth):
    p = HeightMap(synth.profile("exponential", (1e-9, 1e-6), 256, 1e-7, 0), (1e-7,), "line", "h")
    m = HeightMap(synth.surface("exponential", (1e-9, 1e-6), 64, 1e-7, 0), (1e-7, 1e-7), "m", "h")
    with pytest.raises(AdapterError, match="line: is a line profile.*--kind 1d"):
        labbrdf.psd(m, p, kind="2d")
    assert labbrdf.psd(m, p).kind == "1d"  # auto: the profile PSD of both


@pytest.mark.shared
def test_real_maps_through_psd_band_and_k_correlation_fit(real_exports, capsys):
    topo = real_exports / "topography"
    files = [str(topo / n) for n in ("di-1.di", "metropro-1.dat")]
    res = labbrdf.psd(files, fit="k-correlation")
    di, mp = res.spectra
    # the band from each map's pixel and size (512 x 0.977 nm AFM; 640 x 1.098 um MetroPro)
    assert di.band == pytest.approx((1 / 500e-9, 1 / (2 * 500e-9 / 512)), rel=1e-9, abs=0)
    assert mp.band[1] == pytest.approx(1 / (2 * mp.pixel_size[0]), rel=1e-12, abs=0)
    assert mp.band[0] == pytest.approx(1 / (640 * mp.pixel_size[0]), rel=1e-12, abs=0)
    assert res.fit is not None and np.isfinite(res.fit.values["C"])
    assert res.fit.band[0] >= mp.band[0] and res.fit.band[1] <= di.band[1]
    assert any("no map covers" in w for w in res.warnings)  # AFM and MetroPro bands do not meet
    # sigma over each map's band by Parseval is the map's RMS height within the window's
    # variance bias (the Hann window keeps the expected, not the sample, variance)
    from labbrdf.roughness.topography import roughness_statistics

    for s, f in zip(res.spectra, files, strict=True):
        hm = labbrdf.read_height_map(f)
        st = roughness_statistics(hm.heights, hm.pixel_size, blocks=0)
        assert 0.5 < s.band_sigma(0, np.inf) / st.sigma < 2.0
    assert main(["psd", str(topo / "opdx-3.opdx"), "--fit", "fractal", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["kind"] == "1d" and d["fit"]["model"] == "fractal"
    assert main(["psd", str(topo / "opdx-3.opdx"), "--kind", "2d"]) == 2
    assert "opdx-3.opdx: is a line profile" in capsys.readouterr().err
