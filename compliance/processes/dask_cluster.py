"""The Dask side of the one executor: the ``--scheduler`` address, the client, one session per run.

``--scheduler`` (every command that runs parallel work spells it the same way) is either
``local:N`` - a ``distributed.LocalCluster`` of N worker processes on the loopback interface,
started here and stopped with the run - or the address of a running Dask scheduler
(``tcp://host:8786``). Without it the work runs on the local process pool
(:func:`compliance.processes.stopping.worker_pool`).
"""

from __future__ import annotations

import copyreg
import types
from contextlib import contextmanager

from compliance.errors import InputError

__all__ = ["CONNECT_TIMEOUT", "DASK_SCHEMES", "check_reachable", "dask_client", "dask_session", "parse_scheduler"]

DASK_SCHEMES = ("tcp", "tls", "inproc", "ucx", "ws", "wss")  # what distributed.comm knows
CONNECT_TIMEOUT = 5.0  # [s] a TCP connect to a live scheduler takes milliseconds; our choice of margin


def _mappingproxy(d):
    return types.MappingProxyType(d)


# Configurations are frozen with MappingProxyType, which pickle cannot carry; Dask pickles the
# context it scatters, so teach pickle to send the underlying dict and rebuild the proxy.
copyreg.pickle(types.MappingProxyType, lambda m: (_mappingproxy, (dict(m),)))


def parse_scheduler(text: str | None) -> tuple[str, object]:
    """``None`` -> ("local", None); ``"local:N"`` -> ("dask-local", N); ``"tcp://h:p"`` -> ("dask", address).

    Raises
    ------
    InputError
        Not ``local:N`` with N >= 1, or an address whose scheme Dask cannot connect with (checked
        before any work starts).
    """
    if text is None or text == "local":
        return "local", None
    if text.startswith("local:"):
        try:
            n = int(text.split(":", 1)[1])
        except ValueError:
            n = 0
        if n < 1:
            raise InputError(f"--scheduler {text}: expected local:N with N >= 1 workers")
        return "dask-local", n
    if "://" in text:
        scheme, location = text.split("://", 1)
        if scheme not in DASK_SCHEMES:
            raise InputError(f"--scheduler {text}: unknown address scheme; expected one of "
                             f"{', '.join(s + '://' for s in DASK_SCHEMES)} (e.g. tcp://host:8786) or local:N")
        if scheme in ("tcp", "tls"):
            _check_host_port(text, location)
        return "dask", text
    raise InputError(f"--scheduler {text}: expected a Dask scheduler address (tcp://host:8786) or local:N")


def _check_host_port(text: str, location: str) -> None:
    """A TCP address that can exist: a host, and a port 1..65535 when one is given (checked before any work)."""
    host, sep, port = location.rpartition(":") if not location.endswith("]") else (location, "", "")
    if not sep:
        host, port = location, ""
    host = host.strip("[]")
    if not host:
        raise InputError(f"--scheduler {text}: no host; expected tcp://host:8786")
    if port:
        if not port.isdigit() or not 1 <= int(port) <= 65535:
            raise InputError(f"--scheduler {text}: port '{port}' is not a TCP port (1 .. 65535); a Dask scheduler "
                             "listens on 8786 unless told otherwise")


def dask_client(kind: str, target):
    """(client, cluster or None) for a parsed scheduler: a new ``LocalCluster`` for ``dask-local``."""
    from distributed import Client, LocalCluster

    if kind == "dask-local":
        import dask

        # a task whose worker dies comes straight back as KilledWorker, so that govcheck resubmits
        # it and counts the retry (the scheduler's own silent rescheduling would hide it)
        with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
            cluster = LocalCluster(n_workers=target, threads_per_worker=1, processes=True, host="127.0.0.1",
                                   dashboard_address="127.0.0.1:0")
        return Client(cluster), cluster
    _refuse_unreachable(target)
    try:
        return Client(target, timeout=30), None
    except OSError as exc:
        raise InputError(f"--scheduler {target}: cannot reach the Dask scheduler ({exc})") from None
    except Exception as exc:  # a service that is not Dask answers with bytes Dask's handshake cannot read
        raise InputError(f"--scheduler {target}: something answers there, but not as a Dask scheduler "
                         f"({exc.__class__.__name__}: {str(exc)[:120]})") from None


def check_reachable(text: str | None) -> None:
    """``--scheduler`` parsed, and a TCP scheduler address reached (one connect, before any work starts).

    An ``inproc://`` address is refused here, at the command line: it names a scheduler inside the
    same Python process (a library caller's in-process cluster may pass one to ``map_tasks``), and a
    govcheck command starts none.
    """
    kind, target = parse_scheduler(text)
    if kind == "dask" and target.startswith("inproc://"):
        raise InputError(f"--scheduler {text}: an inproc:// address names a scheduler inside the same Python process, "
                         "and a govcheck command starts none; give tcp://host:8786 for a running cluster or local:N")
    if kind == "dask":
        _refuse_unreachable(target)


def _refuse_unreachable(target: str) -> None:
    """Fail fast on a TCP scheduler address nothing listens on (Dask's Client retries for 30 s).

    One plain TCP connect, ``CONNECT_TIMEOUT`` at most: a refused connection (nothing on that
    port, loopback answers at once), an unknown host or a silent address is an
    :class:`InputError`. Other transports (``inproc``, ``ucx``, ...) are left to Dask.
    """
    import socket

    from distributed.comm.addressing import parse_address, parse_host_port

    scheme, location = parse_address(target)
    if scheme not in ("tcp", "tls"):
        return
    try:
        host, port = parse_host_port(location, default_port=8786)
    except ValueError as exc:
        raise InputError(f"--scheduler {target}: not a host:port address ({exc})") from None
    try:
        with socket.create_connection((host, port), timeout=CONNECT_TIMEOUT):
            return
    except socket.timeout:
        why = f"no answer within {CONNECT_TIMEOUT:g} s"
    except OSError as exc:
        why = exc.strerror or str(exc)
    raise InputError(
        f"--scheduler {target}: cannot reach the Dask scheduler at {host}:{port} ({why}); start one there "
        f"(dask scheduler --port {port}) or use --scheduler local:N"
    )


@contextmanager
def dask_session(scheduler: str | None, client=None):
    """One Dask client for a whole run of several ``map_tasks`` calls (a sweep and its remedies).

    Yields ``client`` when one is given, None for the local pool, else a client connected to
    ``scheduler`` (a ``LocalCluster`` started for ``local:N``), closed on exit.
    """
    kind, target = parse_scheduler(scheduler)
    if client is not None or kind == "local":
        yield client
        return
    own, cluster = dask_client(kind, target)
    try:
        yield own
    finally:
        own.close()
        if cluster is not None:
            cluster.close()
