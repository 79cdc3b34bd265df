"""The dask cluster is not open to the network.

* ``local`` binds every listening socket (scheduler, its HTTP server, workers, nannies) to
  127.0.0.1 and starts no dashboard unless asked: checked with psutil in a child process,
  so that sockets of other tests cannot mix in.
* ``tls://``: a cluster with mutual TLS (certificates made here with the ``openssl``
  command) gives the serial numbers for a batch fit and a trace, reached through
  :func:`labbrdf.parallel.configure` (the CLI's ``--tls-*``) and through the dask config;
  a client without a certificate is refused.
* a ``tcp://`` address of another host prints a warning that it is unauthenticated.
"""

from __future__ import annotations

import builtins
import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest

from labbrdf import parallel
from labbrdf.cli import main
from labbrdf.fit import fit_many
from labbrdf.tracer import trace

pytest.importorskip("dask.distributed")

from test_scaleout import TRACE, assert_same_table, assert_same_trace, batch_frame  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(autouse=True)
def _reset_options() -> Any:
    options = getattr(parallel, "_OPTIONS", {})
    saved = dict(options)
    yield
    parallel.shutdown()
    options.clear()
    options.update(saved)


LISTEN = textwrap.dedent(
    """
    import json, sys
    import psutil
    from labbrdf import parallel

    def main():
        assert parallel.run(abs, [-1, 2], scheduler="local", workers=2) == [1, 2]
        client = parallel._LOCAL["client"]
        me = psutil.Process()
        listen = []
        for p in [me, *me.children(recursive=True)]:
            for c in p.net_connections(kind="inet"):
                if c.status == psutil.CONN_LISTEN:
                    listen.append([p.pid, c.laddr.ip, c.laddr.port])
        info = client.scheduler_info()
        addresses = [info["address"]]
        for w, v in info["workers"].items():
            addresses += [w, v.get("nanny")]
        print(json.dumps({"listen": listen, "addresses": addresses,
                          "services": info.get("services", {}),
                          "pids": len(me.children(recursive=True))}))
        parallel.shutdown()

    if __name__ == "__main__":
        main()
    """
)


def _run_listen(env_extra: dict[str, str]) -> dict[str, Any]:
    pytest.importorskip("psutil")
    env = {**os.environ, "PYTHONPATH": str(ROOT), **env_extra}
    r = subprocess.run(
        [sys.executable, "-c", LISTEN], capture_output=True, text=True, env=env, timeout=180
    )
    assert r.returncode == 0, r.stderr[-2000:]
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_local_cluster_listens_on_loopback_only_and_has_no_dashboard():
    info = _run_listen({"LABBRDF_DASK_DASHBOARD": ""})
    assert info["pids"] >= 2  # the worker processes were inspected too
    assert info["listen"], info
    for pid, ip, port in info["listen"]:
        assert ip == "127.0.0.1", f"pid {pid} listens on {ip}:{port}"
    for a in info["addresses"]:
        assert a.startswith("tcp://127.0.0.1:"), a
    # dask always runs the scheduler's HTTP server (/health, /metrics; listed as
    # "dashboard"): checked above to be on 127.0.0.1 like every other socket


def test_dashboard_only_when_asked_and_on_loopback():
    pytest.importorskip("bokeh")
    info = _run_listen({"LABBRDF_DASK_DASHBOARD": "1"})
    port = info["services"]["dashboard"]
    assert any(ip == "127.0.0.1" and p == port for _, ip, p in info["listen"])
    for _, ip, _ in info["listen"]:
        assert ip == "127.0.0.1"


# --------------------------------------------------------------------------- TLS


@pytest.fixture(scope="module")
def certs(tmp_path_factory) -> dict[str, str]:
    """A CA and one certificate it signed (for 127.0.0.1/localhost), made with openssl."""
    if shutil.which("openssl") is None:
        pytest.skip("the openssl command is not installed")
    d = tmp_path_factory.mktemp("tls")

    def ossl(*args: str) -> None:
        subprocess.run(["openssl", *args], cwd=d, check=True, capture_output=True, timeout=60)

    days = ["-days", "2"]
    ossl("req", "-x509", "-newkey", "rsa:2048", "-nodes", *days, "-subj", "/CN=labbrdf CA",
         "-keyout", "ca.key", "-out", "ca.pem")  # fmt: skip
    ossl("req", "-newkey", "rsa:2048", "-nodes", "-subj", "/CN=localhost",
         "-keyout", "node.key", "-out", "node.csr")  # fmt: skip
    (d / "ext.cnf").write_text(
        "subjectAltName=IP:127.0.0.1,DNS:localhost\nextendedKeyUsage=serverAuth,clientAuth\n"
    )
    ossl("x509", "-req", "-in", "node.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
         "-CAcreateserial", *days, "-extfile", "ext.cnf", "-out", "node.pem")  # fmt: skip
    return {
        k: str(d / f) for k, f in (("ca", "ca.pem"), ("cert", "node.pem"), ("key", "node.key"))
    }


@pytest.fixture(scope="module")
def serial() -> tuple[Any, Any, Any]:
    frame = batch_frame(n_wl=2)
    return (
        frame,
        fit_many(frame, "smooth3", scheduler="serial", progress=False),
        trace(TRACE, map=builtins.map),
    )


def _tls_cluster(certs: dict[str, str]) -> Any:
    from distributed import LocalCluster
    from distributed.security import Security

    sec = Security(
        tls_ca_file=certs["ca"],
        tls_scheduler_cert=certs["cert"],
        tls_scheduler_key=certs["key"],
        tls_worker_cert=certs["cert"],
        tls_worker_key=certs["key"],
        tls_client_cert=certs["cert"],
        tls_client_key=certs["key"],
        require_encryption=True,
    )
    return LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        protocol="tls://",
        security=sec,
        dashboard_address=None,
        scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
    )


@pytest.mark.slow
def test_tls_scheduler_gives_serial_numbers_and_refuses_a_client_without_certificate(
    certs, serial
):
    import functools

    frame, table0, trace0 = serial
    with _tls_cluster(certs) as cluster:
        addr = cluster.scheduler_address
        assert addr.startswith("tls://127.0.0.1:")
        # without certificates: a clear error before anything runs
        with pytest.raises(parallel.ParallelError, match="needs certificates"):
            parallel.run(abs, [1], scheduler=addr)
        # a client with no certificate cannot talk to the cluster
        from distributed import Client

        with pytest.raises(Exception):  # noqa: B017 - TLS handshake or timeout error
            Client(addr.replace("tls://", "tcp://"), timeout="3s", set_as_default=False)
        parallel.configure(tls_ca=certs["ca"], tls_cert=certs["cert"], tls_key=certs["key"])
        table = fit_many(frame, "smooth3", scheduler=addr, chunks=3, progress=False)
        assert_same_table(table0, table)
        res = trace(TRACE, map=functools.partial(parallel.imap, scheduler=addr))
        assert_same_trace(trace0, res)


@pytest.mark.slow
def test_tls_from_the_dask_config_and_a_local_cluster_on_tls(certs, serial):
    import dask

    frame, table0, _ = serial
    cfg = {
        "distributed.comm.tls.ca-file": certs["ca"],
        "distributed.comm.tls.client.cert": certs["cert"],
        "distributed.comm.tls.client.key": certs["key"],
    }
    with dask.config.set(cfg):
        table = fit_many(frame, "smooth3", scheduler="local", workers=2, chunks=3, progress=False)
        info = parallel._LOCAL["client"].scheduler_info()
        assert info["address"].startswith("tls://127.0.0.1:")
        assert all(w.startswith("tls://127.0.0.1:") for w in info["workers"])
    assert_same_table(table0, table)


def test_cli_tls_options_need_existing_files(tmp_path, capsys):
    scan = ROOT / "fixtures" / "specular" / "osr_specular.csv"
    argv = ["fit", str(scan), "--model", "smooth3", "--scheduler", "tls://127.0.0.1:1"]
    assert main([*argv, "--tls-ca", str(tmp_path / "nope.pem"), "--tls-cert", "x"]) == 2
    assert "nope.pem" in capsys.readouterr().err
    assert main([*argv, "--tls-key", str(tmp_path / "k.pem")]) == 2
    assert "--tls-ca" in capsys.readouterr().err
    assert main(argv) == 2  # tls:// without certificates
    assert "needs certificates" in capsys.readouterr().err


# --------------------------------------------------------------------------- tcp


def test_tcp_to_another_host_warns_that_it_is_unauthenticated(monkeypatch, capsys):
    class Refused:
        def __init__(self, *a: Any, **k: Any) -> None:
            raise OSError("connection refused")

    monkeypatch.setattr(parallel, "_import_dask", lambda: (Refused, None))
    with pytest.raises(parallel.ParallelError, match="cannot reach"):
        parallel.run(abs, [1], scheduler="tcp://192.0.2.7:8786")
    err = capsys.readouterr().err
    assert "WARNING" in err and "unauthenticated" in err and "tls://" in err
    with pytest.raises(parallel.ParallelError):
        parallel.run(abs, [1], scheduler="tcp://127.0.0.1:8786")
    assert "unauthenticated" not in capsys.readouterr().err  # this machine: no warning
