"""Optics core: Fresnel amplitudes, Stokes/Mueller algebra, psi/Delta of a bare substrate.

Pure NumPy (physics layer): no pandas I/O, matplotlib or nlopt. Every public function is
vectorised with NumPy broadcasting; angles are in degrees at the public API (radians inside).
Outputs are ndarrays (0-d for scalar inputs).

Conventions (the ONE labbrdf convention, "LB"; also in ``docs/conventions.md``)
-------------------------------------------------------------------------------
* Time dependence ``exp(-i omega t)``; complex index ``N = n + ik`` with ``k >= 0`` for an
  absorbing medium. A plane wave travels as ``exp(+i k0 (kx x + kz z))``, so the physical
  root of ``kz = N cos(theta)`` has ``Im(kz) >= 0`` (it decays away from the interface) and,
  for a lossless medium, ``Re(kz) >= 0`` (it carries energy away).
* Stokes frames: each ray has its own right-handed frame ``{s, p, k}``, with
  ``s = phi_hat(phi) = (-sin phi, cos phi, 0)`` (``phi`` the azimuth of the ray: phi_i for
  the incident ray, phi_r for the outgoing one; at theta = 0 the same formula with the bin's
  phi) and ``p = k x s``. The sign of ``s`` does not matter for a Stokes vector (flipping s
  also flips p).
* Stokes vector ``[S0, S1, S2, S3]`` with ``S1 = |Es|^2 - |Ep|^2`` (``S1 = +1``:
  s-polarised), ``S2 = 2 Re(Es Ep*)`` (``S2 = +1``: linear along ``(s + p)/sqrt 2``),
  ``S3 = 2 Im(Es* Ep) = -2 Im(Es Ep*)`` with the complex amplitudes of ``exp(-i omega t)``:
  ``S3 = +1`` means the field rotates from s towards p (``Es = 1``, ``Ep = i`` gives
  ``E(t) = cos(wt) s + sin(wt) p``), i.e. counter-clockwise for a receiver looking back at
  the source. Compactly, ``S2 + i S3 = 2 Es* Ep``. This is SCATMECH's convention (it calls
  the state LCP); Mitsuba 3 gives the same state ``S3 = -1``
  (``M_LB = D M_mitsuba D``, ``D = diag(1, 1, 1, -1)``).
* Fresnel amplitudes of an interface from medium 1 (``n1``) to medium 2 (``n2``), with
  ``N = n2/n1``: ``rs = (cos_i - N cos_t)/(cos_i + N cos_t)``,
  ``rp = (N cos_i - cos_t)/(N cos_i + cos_t)``, ``ts = 2 cos_i/(cos_i + N cos_t)``,
  ``tp = 2 cos_i/(N cos_i + cos_t)``. At normal incidence ``rp = -rs``, so the reflection
  Mueller matrix has ``M22 = M33 = -R``: a mirror flips S2 and S3 in right-handed frames.
* Every Mueller matrix here maps the Stokes vector in the frame of the incoming ray to the
  Stokes vector in the frame of the outgoing ray (reflected or transmitted), both frames
  built as above. Matrices are ``(..., 4, 4)`` arrays; apply them with ``np.matmul``.
* Ellipsometry: ``rho = tan(psi) exp(i Delta)`` in the Nebraska convention (Muller 1969;
  Azzam and Bashara [2]_), with ``Delta = 180 deg`` at normal incidence and ``0 < Delta < 180``
  for a bare absorber; ``Delta`` is returned in ``[0, 360)``. With the LB amplitudes above
  this is ``tan(psi) = |rp/rs|``, ``Delta = arg(rs rp*)`` (docs/models.md section 3.2: the
  Nebraska rho is the complex conjugate of the LB ``rp/rs``, and (psi, Delta) are the same
  numbers in both conventions). This module computes psi and Delta of a known substrate
  (:func:`psi_delta`); the inverse problem, psi and Delta to an index with its condition
  number, is :mod:`labbrdf.ellipsometry`.

Error policy
------------
Public functions raise ``ValueError`` naming the argument and what was expected for
non-finite input, an index with ``n < 0`` or ``k < 0`` or ``N = 0``, an angle outside
[0, 90] deg, a non-positive wavelength or a negative thickness. No NaN is returned for valid
input, except :func:`dop` of a zero-intensity Stokes vector (documented there).
:func:`fresnel_cos` is the unvalidated hot path for the tracer.

References
----------
.. [1] M. Born, E. Wolf, *Principles of Optics*, 7th ed., Cambridge University Press (1999),
   sections 1.5 (Fresnel formulae) and 1.6 (thin films).
.. [2] R. M. A. Azzam, N. M. Bashara, *Ellipsometry and Polarized Light*, North-Holland
   (1977), sections 4.2-4.3 (the ellipsometric ratio of a bare substrate).
.. [3] X. Zou, L. Bai, Z. Wu, "Mirror reflectance spectrum modeling of smooth samples",
   Acta Optica Sinica 33(6) 0612008 (2013), doi:10.3788/AOS201333.0612008, eqs. (4)-(6).
.. [4] K. Berger, A. Weidlich, A. Wilkie, M. Wimmer, "Modeling and verifying the polarizing
   reflectance of real-world metallic surfaces", IEEE CG&A 32(2) 24-33 (2012).
.. [5] Z. Dong, P. Bai, W. Xu, Y. Liu, X. Sun, "Modeling and characteristic analysis methods
   for reflection polarization on coated surfaces", Acta Optica Sinica 42(22) 2224001
   (2022), doi:10.3788/AOS202242.2224001, eqs. (8), (11), (12), (13), (17); its errors
   are listed in ``docs/errata.md``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "berger_reflectances",
    "dop",
    "fresnel",
    "fresnel_cos",
    "mueller_reflection",
    "mueller_rotation",
    "mueller_transmission",
    "psi_delta",
    "reflectance",
    "transmission_factor",
    "transmittance",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


def _arrays(*values: ArrayLike) -> Any:
    """Return every value as an ndarray (0-d for scalars), for uniform output types.

    Typed ``Any``: a tuple's length and dtypes cannot follow ``*values``; each caller
    declares the precise tuple it returns.
    """
    return tuple(np.asarray(v) for v in values)


# --------------------------------------------------------------------------------------
# input validation
# --------------------------------------------------------------------------------------


def _finite(name: str, value: ArrayLike, dtype: type) -> NDArray:
    """Return ``value`` as an all-finite ndarray of ``dtype``, or raise naming ``name``.

    A complex value for a real argument is refused rather than cast (numpy would silently
    drop the imaginary part).
    """
    if dtype is np.float64 and np.iscomplexobj(value):
        raise ValueError(f"{name}: expected real values, got complex")
    try:
        arr: NDArray[Any] = np.asarray(value, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name}: expected a number or an array of numbers ({exc})") from None
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: expected finite values, got NaN or inf")
    return arr


def _index(name: str, value: ArrayLike) -> ComplexArray:
    """Complex index N = n + ik with n >= 0, k >= 0 and N != 0."""
    arr = _finite(name, value, np.complex128)
    if np.any(arr.real < 0):
        raise ValueError(f"{name}: the real part n of N = n + ik must be >= 0")
    if np.any(arr.imag < 0):
        raise ValueError(
            f"{name}: the extinction coefficient k of N = n + ik must be >= 0 "
            "(labbrdf uses N = n + ik with exp(-i omega t); absorbing media have k > 0)"
        )
    if np.any(arr == 0):
        raise ValueError(f"{name}: the index N = n + ik must not be 0")
    return arr


def _real_index(name: str, value: ArrayLike) -> FloatArray:
    """A real, strictly positive (lossless) index."""
    arr = np.asarray(value)
    if np.iscomplexobj(arr):
        if np.any(arr.imag != 0):
            raise ValueError(f"{name}: expected a real (lossless) index, got a complex one")
        arr = arr.real
    arr = _finite(name, arr, np.float64)
    if np.any(arr <= 0):
        raise ValueError(f"{name}: expected a real index > 0")
    return arr


def _angle(name: str, value: ArrayLike, *, open_ends: bool = False) -> FloatArray:
    arr = _finite(name, value, np.float64)
    if open_ends:
        if np.any((arr <= 0) | (arr >= 90)):
            raise ValueError(f"{name}: expected an angle in the open interval (0, 90) deg")
    elif np.any((arr < 0) | (arr > 90)):
        raise ValueError(f"{name}: expected an angle in [0, 90] deg")
    return arr


def _nonneg(name: str, value: ArrayLike, *, strict: bool = False) -> FloatArray:
    arr = _finite(name, value, np.float64)
    if strict and np.any(arr <= 0):
        raise ValueError(f"{name}: expected values > 0")
    if not strict and np.any(arr < 0):
        raise ValueError(f"{name}: expected values >= 0")
    return arr


# --------------------------------------------------------------------------------------
# Fresnel amplitudes
# --------------------------------------------------------------------------------------


def _physical_root(w: ComplexArray) -> ComplexArray:
    """Square root of ``w`` with the branch cut on the negative imaginary axis.

    Returns the root ``r`` with ``Re(r) + Im(r) >= 0``, i.e. ``arg r`` in (-pi/4, 3pi/4].
    For ``Im(w) >= 0`` (always the case for a lossless incidence medium, because
    ``Im(n2^2) = 2 n2 k2 >= 0``) this is the principal root, with ``Re, Im >= 0``: the
    transmitted wave decays and propagates away from the interface. The rule also settles
    a signed zero (``w = -x - 0j`` would give ``-i sqrt(x)`` from ``np.sqrt``) and, for an
    absorbing incidence medium (complex ``kx``), keeps the forward root of a propagating
    wave and the decaying root of an evanescent one.
    """
    r = np.sqrt(w)
    return np.where(r.real + r.imag < 0, -r, r)


def _kz(
    n1: ComplexArray, n2: ComplexArray, cos_i: NDArray[np.float64] | float
) -> tuple[ComplexArray, ComplexArray]:
    """Normal wave-vector components ``n1 cos_i`` and ``n2 cos_t`` [1, in units of k0].

    ``(n2 cos_t)^2 = n2^2 - n1^2 sin^2 = (n2^2 - n1^2) + (n1 cos_i)^2``; the second form is
    exact for identical media (``kz2 = kz1``, no spurious reflection at grazing incidence).
    """
    kz1 = n1 * cos_i
    kz2 = _physical_root((n2 * n2 - n1 * n1) + kz1 * kz1)
    return kz1, kz2


def _amplitudes(
    n1: ComplexArray, n2: ComplexArray, kz1: ComplexArray, kz2: ComplexArray
) -> tuple[ComplexArray, ComplexArray, ComplexArray, ComplexArray]:
    """rs, rp, ts, tp from the indices and the normal wave-vector components.

    ``kz1 = n1 cos_i`` and ``kz2 = n2 cos_t`` may both be complex (inside an absorbing film).
    """
    n1sq_kz2 = n1 * n1 * kz2
    n2sq_kz1 = n2 * n2 * kz1
    den_s = kz1 + kz2
    den_p = n2sq_kz1 + n1sq_kz2
    degenerate = (den_s == 0) | (den_p == 0)
    if np.any(degenerate):
        den_s = np.where(degenerate, 1.0, den_s)
        den_p = np.where(degenerate, 1.0, den_p)
    rs = (kz1 - kz2) / den_s
    rp = (n2sq_kz1 - n1sq_kz2) / den_p
    ts = 2.0 * kz1 / den_s
    tp = 2.0 * n1 * n2 * kz1 / den_p
    if np.any(degenerate):
        rs = np.where(degenerate, 0.0, rs)
        rp = np.where(degenerate, 0.0, rp)
        ts = np.where(degenerate, 1.0, ts)
        tp = np.where(degenerate, n1 / n2, tp)  # 1 for identical media
    return rs, rp, ts, tp


def fresnel_cos(
    n1: ArrayLike, n2: ArrayLike, cos_i: ArrayLike
) -> tuple[ComplexArray, ComplexArray, ComplexArray, ComplexArray, ComplexArray]:
    """Fresnel amplitudes from the cosine of the angle of incidence (tracer hot path).

    Parameters
    ----------
    n1, n2 : array_like of complex
        Index ``n + ik`` of the incidence and transmission media [1]. Not validated.
    cos_i : array_like of float
        Cosine of the angle of incidence, real in [0, 1] [1]. Not validated.

    Returns
    -------
    rs, rp, ts, tp : ndarray of complex
        Amplitude reflection and transmission coefficients in the LB convention (module
        docstring) [1]; Born and Wolf [1]_ section 1.5.2, Dong 2022 [5]_ eq. (8)
        (see Notes).
    cos_t : ndarray of complex
        Cosine of the (complex) angle of refraction, physical branch: ``n2 cos_t`` has
        ``Im >= 0`` and, when real, ``Re >= 0`` [1]. Purely imaginary under total internal
        reflection.

    Notes
    -----
    * Dong 2022 eq. (8) prints ``rs = (sqrt(n^2 - sin^2) - cos)/(sqrt(n^2 - sin^2) + cos)``,
      the negative of ``rs`` here, with the same ``rp``: that is the "rp = +rs at normal
      incidence" convention, which flips the sign of the S2/S3 block of eq. (11) (pitfall 10
      of the oracles README). labbrdf uses the LB sign throughout.
    * Written as ``rs = (kz1 - kz2)/(kz1 + kz2)``,
      ``rp = (n2^2 kz1 - n1^2 kz2)/(n2^2 kz1 + n1^2 kz2)``, ``ts = 2 kz1/(kz1 + kz2)``,
      ``tp = 2 n1 n2 kz1/(n2^2 kz1 + n1^2 kz2)`` with ``kz1 = n1 cos_i``,
      ``kz2 = n2 cos_t``: no division by ``n2`` or by ``cos_t``, finite at the critical
      angle (``rs = rp = 1``) and at grazing incidence (``rs = rp = -1``).
    * For identical media at exactly ``cos_i = 0`` all denominators vanish; the limit (no
      interface: ``r = 0``, ``t = 1``) is returned.
    * An absorbing incidence medium is handled formally (real angle, complex ``kx``); see
      the caveat in :func:`transmittance`.
    """
    n1 = np.asarray(n1, dtype=np.complex128)
    n2 = np.asarray(n2, dtype=np.complex128)
    kz1, kz2 = _kz(n1, n2, np.asarray(cos_i, dtype=np.float64))
    rs, rp, ts, tp = _amplitudes(n1, n2, kz1, kz2)
    cos_t = kz2 / n2
    return _arrays(rs, rp, ts, tp, cos_t)


def _cos_deg(name: str, theta_deg: ArrayLike) -> FloatArray:
    return np.cos(np.radians(_angle(name, theta_deg)))


def fresnel(
    n1: ArrayLike, n2: ArrayLike, theta_i_deg: ArrayLike
) -> tuple[ComplexArray, ComplexArray, ComplexArray, ComplexArray]:
    """Fresnel amplitude coefficients of a planar interface (LB convention).

    Parameters
    ----------
    n1 : array_like of complex
        Index ``n + ik`` of the incidence medium (``n >= 0``, ``k >= 0``) [1].
    n2 : array_like of complex
        Index ``n + ik`` of the transmission medium [1].
    theta_i_deg : array_like of float
        Angle of incidence in [0, 90] [deg].

    Returns
    -------
    rs, rp, ts, tp : ndarray of complex
        Amplitude reflection and transmission coefficients [1], broadcast over the inputs.
        Born and Wolf [1]_ section 1.5.2; see :func:`fresnel_cos` for the exact form, the
        branch of ``cos_t`` (total internal reflection, grazing incidence) and the sign
        convention (Notes there).

    Raises
    ------
    ValueError
        For non-finite input, ``n < 0``, ``k < 0``, ``N = 0`` or an angle outside [0, 90].

    Examples
    --------
    >>> rs, rp, ts, tp = fresnel(1.0, 1.5, 0.0)
    >>> float(rs.real), float(rp.real)
    (-0.2, 0.2)
    """
    n1 = _index("n1", n1)
    n2 = _index("n2", n2)
    cos_i = _cos_deg("theta_i_deg", theta_i_deg)
    rs, rp, ts, tp, _ = fresnel_cos(n1, n2, cos_i)
    return rs, rp, ts, tp


def reflectance(
    n1: ArrayLike, n2: ArrayLike, theta_i_deg: ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Power reflectances ``Rs = |rs|^2``, ``Rp = |rp|^2`` (Dong 2022 [5]_ eq. (9)).

    Parameters
    ----------
    n1, n2 : array_like of complex
        Indices ``n + ik`` of the incidence and transmission media [1].
    theta_i_deg : array_like of float
        Angle of incidence in [0, 90] [deg].

    Returns
    -------
    Rs, Rp : ndarray of float
        s- and p-polarised reflectance, fractions in [0, 1] [1].
    """
    rs, rp, _, _ = fresnel(n1, n2, theta_i_deg)
    return _arrays(np.abs(rs) ** 2, np.abs(rp) ** 2)


def transmission_factor(
    n1: ArrayLike, n2: ArrayLike, cos_i: ArrayLike, cos_t: ArrayLike
) -> FloatArray:
    """Beam-area (Poynting) factor ``Re(n2 cos_t) / Re(n1 cos_i)`` of a transmitted beam.

    Parameters
    ----------
    n1, n2 : array_like of complex
        Indices of the incidence and transmission media [1]. Not validated.
    cos_i : array_like of float
        Cosine of the angle of incidence, in [0, 1] [1].
    cos_t : array_like of complex
        Cosine of the angle of refraction as returned by :func:`fresnel_cos` [1].

    Returns
    -------
    ndarray of float
        ``Re(n2 cos_t) / Re(n1 cos_i)`` [1]: 0 under total internal reflection; the factor
        that turns ``|ts|^2`` into the s transmittance and that scales
        :func:`mueller_transmission`. 0 where ``Re(n1 cos_i) = 0`` (grazing incidence,
        where no power crosses the interface).
    """
    num = np.real(np.asarray(n2) * np.asarray(cos_t))
    den = np.real(np.asarray(n1) * np.asarray(cos_i))
    safe = np.where(den == 0, 1.0, den)
    return np.asarray(np.where(den == 0, 0.0, num / safe))


def transmittance(
    n1: ArrayLike, n2: ArrayLike, theta_i_deg: ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Power transmittances ``Ts``, ``Tp`` with the beam-area factor (Born and Wolf 1.5.3).

    Parameters
    ----------
    n1, n2 : array_like of complex
        Indices ``n + ik`` of the incidence and transmission media [1].
    theta_i_deg : array_like of float
        Angle of incidence in [0, 90] [deg].

    Returns
    -------
    Ts, Tp : ndarray of float
        Fraction of the incident s / p power flux (normal component of the Poynting vector)
        that crosses the interface [1]. ``Rs + Ts = Rp + Tp = 1`` at any interface with a
        lossless incidence medium (``n1`` real), including an absorbing ``n2`` and total
        internal reflection (``T = 0``).

    Notes
    -----
    * ``Ts = |ts|^2 Re(n2 cos_t) / Re(n1 cos_i)`` and
      ``Tp = |tp|^2 Re(conj(n2) cos_t) / Re(conj(n1) cos_i)``: the p wave's magnetic field is
      ``n E``, so its Poynting flux carries ``conj(n)``. Both factors equal
      :func:`transmission_factor` when ``n2`` (and ``n1``) are real; for an absorbing ``n2``
      they differ and only this form gives ``Rp + Tp = 1`` (it is also tmm's form).
    * Dong 2022 [5]_ eq. (10) sets ``T = 1 - R``, true only for a lossless interface; here
      ``T`` is computed from the amplitudes and ``R + T = 1`` is a test.
    * Absorbing-ambient caveat: if ``n1`` is absorbing, the incident and reflected waves
      interfere in the normal Poynting flux, the "angle of incidence" is a formal real
      angle with complex ``kx = n1 sin(theta)``, and ``R + T != 1`` in general. The values
      are then the usual formal ones (power just below the interface over incident power
      just above it, each computed as if alone).
    * At 90 deg no power crosses: ``T`` is 0 up to round-off (``cos(90 deg)`` evaluates to
      6e-17).
    """
    n1c = _index("n1", n1)
    n2c = _index("n2", n2)
    cos_i = _cos_deg("theta_i_deg", theta_i_deg)
    _, _, ts, tp, cos_t = fresnel_cos(n1c, n2c, cos_i)
    ts_fac = transmission_factor(n1c, n2c, cos_i, cos_t)
    tp_fac = transmission_factor(np.conj(n1c), np.conj(n2c), cos_i, cos_t)
    return _arrays(np.abs(ts) ** 2 * ts_fac, np.abs(tp) ** 2 * tp_fac)


# --------------------------------------------------------------------------------------
# Stokes / Mueller algebra
# --------------------------------------------------------------------------------------


def _mueller_sp(a: FloatArray, b: FloatArray, c: ComplexArray) -> FloatArray:
    """Mueller matrix of an element that does not couple s and p.

    ``a``, ``b`` are the s and p intensity gains, ``c`` the s-p coherence gain: ``|js|^2``,
    ``|jp|^2``, ``js jp*`` for a diagonal Jones matrix ``diag(js, jp)``, or incoherent sums
    of such terms (then ``|c|^2 < a b``: a partially depolarising matrix).
    """
    a, b, c = np.broadcast_arrays(a, b, c)
    m = np.zeros(a.shape + (4, 4))
    m[..., 0, 0] = m[..., 1, 1] = 0.5 * (a + b)
    m[..., 0, 1] = m[..., 1, 0] = 0.5 * (a - b)
    m[..., 2, 2] = m[..., 3, 3] = c.real
    m[..., 2, 3] = c.imag
    m[..., 3, 2] = -c.imag
    return m


def mueller_reflection(rs: ArrayLike, rp: ArrayLike) -> FloatArray:
    """Mueller matrix of specular reflection from the amplitudes (Dong 2022 [5]_ eq. (11)).

    Parameters
    ----------
    rs, rp : array_like of complex
        Amplitude reflection coefficients in the LB convention [1].

    Returns
    -------
    ndarray of float, shape (..., 4, 4)
        ``1/2 [[Rs+Rp, Rs-Rp, 0, 0], [Rs-Rp, Rs+Rp, 0, 0], [0, 0, 2 Re(rs rp*),
        2 Im(rs rp*)], [0, 0, -2 Im(rs rp*), 2 Re(rs rp*)]]`` [1], from the frame of the
        incident ray to that of the reflected ray (module docstring). With LB amplitudes
        ``M22 = M33 = -R`` at normal incidence.

    Raises
    ------
    ValueError
        For non-finite input.

    Notes
    -----
    Dong 2022 eq. (11) has the same layout but, evaluated with the paper's own amplitudes
    (eq. (8), whose ``rs`` is minus the LB ``rs``), it gives ``M22 = M33 = -Re(rs rp*)``
    (``+R`` at normal incidence) with ``M23 = +Im(rs rp*)``: not a consistent right-handed
    convention. labbrdf uses the LB matrix above, which SCATMECH and tmm reproduce to
    3e-14 and Mitsuba 3 after ``D M D`` (oracles README section 6).
    """
    rs = _finite("rs", rs, np.complex128)
    rp = _finite("rp", rp, np.complex128)
    return _mueller_sp(np.abs(rs) ** 2, np.abs(rp) ** 2, rs * np.conj(rp))


def mueller_transmission(ts: ArrayLike, tp: ArrayLike, factor: ArrayLike) -> FloatArray:
    """Mueller matrix of transmission through an interface, from the amplitudes.

    Parameters
    ----------
    ts, tp : array_like of complex
        Amplitude transmission coefficients in the LB convention [1].
    factor : array_like of float
        Beam-area factor ``Re(n2 cos_t) / Re(n1 cos_i)`` (:func:`transmission_factor`),
        >= 0 [1].

    Returns
    -------
    ndarray of float, shape (..., 4, 4)
        ``factor/2 [[Ts'+Tp', Ts'-Tp', 0, 0], [Ts'-Tp', Ts'+Tp', 0, 0], [0, 0,
        2 Re(ts tp*), 2 Im(ts tp*)], [0, 0, -2 Im(ts tp*), 2 Re(ts tp*)]]`` with
        ``Ts' = |ts|^2``, ``Tp' = |tp|^2`` [1], from the frame of the incident ray to that of
        the refracted ray. At a lossless interface ``M00 = (Ts + Tp)/2`` and
        ``M_reflection + M_transmission`` conserves S0 for every input.

    Raises
    ------
    ValueError
        For non-finite input or ``factor < 0``.

    Notes
    -----
    Dong 2022 [5]_ eq. (12) prints ``-2 sqrt(Ts Tp)`` on the diagonal of the S2/S3 block
    and zeros off it. That is wrong: the matrix follows from the Jones matrix
    ``diag(ts, tp)``; ``ts`` and ``tp`` have the same phase for a lossless interface below
    the critical angle, so the block is ``+2 Re(ts tp*) = +2 |ts tp|`` (scaled), and it has
    off-diagonal ``Im(ts tp*)`` terms otherwise. For an absorbing second medium the p power
    carries ``Re(conj(n2) cos_t)`` rather than ``Re(n2 cos_t)`` (see :func:`transmittance`);
    the single factor then describes the Stokes vector of the inhomogeneous refracted wave
    only approximately, as in any ray tracer.
    """
    ts = _finite("ts", ts, np.complex128)
    tp = _finite("tp", tp, np.complex128)
    factor = _nonneg("factor", factor)
    return factor[..., None, None] * _mueller_sp(
        np.abs(ts) ** 2, np.abs(tp) ** 2, ts * np.conj(tp)
    )


def mueller_rotation(angle_deg: ArrayLike) -> FloatArray:
    """Mueller matrix of a rotation of the Stokes reference frame about the ray.

    Parameters
    ----------
    angle_deg : array_like of float
        Rotation angle [deg], any finite value, positive from s towards p (a right-handed
        rotation about the propagation direction k).

    Returns
    -------
    ndarray of float, shape (..., 4, 4)
        ``[[1, 0, 0, 0], [0, cos 2a, sin 2a, 0], [0, -sin 2a, cos 2a, 0], [0, 0, 0, 1]]`` [1].
        It maps a Stokes vector given in the frame ``{s, p}`` to the same light described in
        the frame ``{s', p'}`` with ``s' = cos(a) s + sin(a) p``. For example light
        polarised along s, ``[1, 1, 0, 0]``, reads ``[1, 0, -1, 0]`` in the frame rotated
        by +45 deg. ``R(a) R(b) = R(a + b)``, ``R(-a) = R(a)^T``.

    Raises
    ------
    ValueError
        For non-finite input.

    Notes
    -----
    Dong 2022 [5]_ eq. (17) prints ``M[0, 0] = 0``, which would annihilate the intensity;
    the correct value is 1. The paper's matrix also has the opposite sign of ``sin``, i.e.
    it rotates by ``-a`` in this sense convention; always state which frame a rotation maps
    to.
    """
    a = np.radians(_finite("angle_deg", angle_deg, np.float64))
    c2, s2 = np.cos(2 * a), np.sin(2 * a)
    m = np.zeros(a.shape + (4, 4))
    m[..., 0, 0] = m[..., 3, 3] = 1.0
    m[..., 1, 1] = m[..., 2, 2] = c2
    m[..., 1, 2] = s2
    m[..., 2, 1] = -s2
    return m


def dop(stokes: ArrayLike) -> FloatArray:
    """Degree of polarization ``sqrt(S1^2 + S2^2 + S3^2) / S0`` (Dong 2022 [5]_ eq. (13)).

    Parameters
    ----------
    stokes : array_like of float, shape (..., 4)
        Stokes vectors along the last axis, ``S0 >= 0`` [any intensity unit].

    Returns
    -------
    ndarray of float, shape (...)
        Degree of polarization [1]. NaN where ``S0 = 0`` (no light: the DOP is undefined),
        without a warning; e.g. empty tracer bins.

    Raises
    ------
    ValueError
        If the last axis does not have length 4, for non-finite input or ``S0 < 0``.
    """
    s = _finite("stokes", stokes, np.float64)
    if s.ndim == 0 or s.shape[-1] != 4:
        raise ValueError(f"stokes: expected shape (..., 4), got {s.shape}")
    s0 = s[..., 0]
    if np.any(s0 < 0):
        raise ValueError("stokes: expected S0 >= 0")
    pol = np.sqrt(s[..., 1] ** 2 + s[..., 2] ** 2 + s[..., 3] ** 2)
    out = np.full(s0.shape, np.nan)
    np.divide(pol, s0, out=out, where=s0 > 0)
    return out


# --------------------------------------------------------------------------------------
# ellipsometric angles of a known substrate (the inversion is labbrdf.ellipsometry)
# --------------------------------------------------------------------------------------


def _wrap360(delta_deg: FloatArray) -> FloatArray:
    d = np.mod(delta_deg, 360.0)
    return np.where(d >= 360.0, 0.0, d)  # np.mod(-1e-20, 360) rounds to 360.0


def psi_delta(
    n: ArrayLike, theta_deg: ArrayLike, n_ambient: ArrayLike = 1.0
) -> tuple[FloatArray, FloatArray]:
    """Ellipsometric angles of a bare substrate, Nebraska convention (Zou 2013 [3]_ eq. (4)).

    Parameters
    ----------
    n : array_like of complex
        Substrate index ``n + ik`` (``k >= 0``) [1].
    theta_deg : array_like of float
        Angle of incidence in [0, 90] [deg].
    n_ambient : array_like of float, optional
        Real index of the (lossless) ambient, > 0 [1]. Default 1.

    Returns
    -------
    psi_deg : ndarray of float
        ``arctan |rp/rs|`` in [0, 90] [deg].
    delta_deg : ndarray of float
        ``Delta`` in [0, 360) [deg], Nebraska convention: 180 at normal incidence, in
        (0, 180) for a bare absorber, 0 or 180 for a lossless dielectric.

    Raises
    ------
    ValueError
        For invalid input (see the module error policy), a complex ``n_ambient``, or
        ``n == n_ambient`` (no interface: psi and Delta are undefined).

    Notes
    -----
    ``rho = tan(psi) exp(i Delta) = rp/rs`` (Zou 2013 eq. (4)) holds literally in the
    Nebraska convention (``exp(+i omega t)``, ``N = n - ik``). labbrdf's amplitudes are LB
    (``exp(-i omega t)``, ``N = n + ik``), whose ``rp/rs`` is the complex conjugate, so
    ``Delta = arg(rs rp*)`` here (docs/models.md section 3.2); the numbers agree with
    pyElli's (psi, Delta).
    """
    nc = _index("n", n)
    n0 = _real_index("n_ambient", n_ambient)
    cos_i = _cos_deg("theta_deg", theta_deg)
    if np.any(nc == n0):
        raise ValueError("n: equals n_ambient, so there is no interface and psi is undefined")
    rs, rp, _, _, _ = fresnel_cos(n0, nc, cos_i)
    psi = np.degrees(np.arctan2(np.abs(rp), np.abs(rs)))
    delta = _wrap360(np.degrees(np.angle(rs * np.conj(rp))))
    return _arrays(psi, delta)


def berger_reflectances(
    n: ArrayLike, k: ArrayLike, theta_deg: ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Fresnel power reflectances ``(F_perp, F_par)`` in Berger's real form, corrected.

    Parameters
    ----------
    n, k : array_like of float
        Real and imaginary parts of the substrate index ``N = n + ik``, both >= 0, not both
        0 [1]. The ambient is vacuum/air (index 1).
    theta_deg : array_like of float
        Angle of incidence ``g`` in [0, 90] [deg].

    Returns
    -------
    F_perp, F_par : ndarray of float
        ``F_perp = ((a - cos g)^2 + b^2)/((a + cos g)^2 + b^2) = |rs|^2`` and
        ``F_par = F_perp ((a - sin g tan g)^2 + b^2)/((a + sin g tan g)^2 + b^2) = |rp|^2``
        [1], with ``a + ib = sqrt(N^2 - sin^2 g)``, i.e. ``2 a^2 = sqrt(q^2 + 4 n^2 k^2) + q``,
        ``2 b^2 = sqrt(q^2 + 4 n^2 k^2) - q``, ``q = n^2 - k^2 - sin^2 g``. Exact for a bare
        substrate: ``F_par / F_perp = tan^2 psi``.

    Raises
    ------
    ValueError
        For non-finite input, ``n < 0``, ``k < 0``, ``n = k = 0`` or an angle outside
        [0, 90].

    Notes
    -----
    Corrected form of docs/models.md section 3.4 (Berger et al. 2012 [4]_ as quoted in
    Zou 2013 [3]_ eqs. (5)-(6)). Two misprints of eqs. (5)-(6) are fixed: the square
    belongs on ``q`` inside the root (``sqrt(q^2 + 4 n^2 k^2)``, eq. (6)), and the
    numerator of eq. (5) needs ``(a - sin g tan g)``, not ``(a - sin g)`` (the two agree only
    at 45 deg). Numerically, the smaller of ``a``, ``b`` is obtained from ``a b = n k``
    instead of the difference ``sqrt(...) - |q|``, which cancels catastrophically for a
    weak absorber (same value, no loss of digits).
    """
    n = _nonneg("n", n)
    k = _nonneg("k", k)
    if np.any((n == 0) & (k == 0)):
        raise ValueError("n, k: the index N = n + ik must not be 0")
    g = np.radians(_angle("theta_deg", theta_deg))
    sin_g, cos_g = np.sin(g), np.cos(g)
    q = n * n - k * k - sin_g * sin_g
    root = np.hypot(q, 2.0 * n * k)
    big = np.sqrt(0.5 * (root + np.abs(q)))  # the larger of a, b
    safe = np.where(big == 0, 1.0, big)
    small = np.where(big == 0, 0.0, n * k / safe)
    a = np.where(q >= 0, big, small)
    b = np.where(q >= 0, small, big)
    st = sin_g * np.tan(g)
    f_perp = ((a - cos_g) ** 2 + b * b) / ((a + cos_g) ** 2 + b * b)
    f_par = f_perp * ((a - st) ** 2 + b * b) / ((a + st) ** 2 + b * b)
    return _arrays(f_perp, f_par)
