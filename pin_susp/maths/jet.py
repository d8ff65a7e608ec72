"""Forward-mode derivatives of the metric functions: dual numbers over numpy.

A :class:`Dual` is a + ε·b with ε² = 0. Run a metric on points given as
Duals (position, velocity) and it returns (value, exact derivative along
that velocity); nest Duals (a Dual whose parts are Duals) and it returns
exact mixed second derivatives too, e.g. the change of camber gain with a
hardpoint. The derivative part may carry extra *leading* axes, one per
direction, so many directions are pushed through at once.

Metric code stays plain numpy: it must index with ``x[..., k]`` and reduce
with ``axis=-1`` so that the leading direction axes pass through. Only the
operations the metrics use are defined; anything else raises TypeError.
"""

from __future__ import annotations

import numpy as np


class Dual:
    __array_priority__ = 1000

    def __init__(self, val, der):
        self.val = val
        self.der = der

    # -- arithmetic -------------------------------------------------------
    def __add__(self, other):
        if isinstance(other, Dual):
            return Dual(self.val + other.val, self.der + other.der)
        return Dual(self.val + other, self.der)

    __radd__ = __add__

    def __neg__(self):
        return Dual(-self.val, -self.der)

    def __sub__(self, other):
        if isinstance(other, Dual):
            return Dual(self.val - other.val, self.der - other.der)
        return Dual(self.val - other, self.der)

    def __rsub__(self, other):
        return Dual(other - self.val, -self.der)

    def __mul__(self, other):
        if isinstance(other, Dual):
            return Dual(self.val * other.val, self.der * other.val + self.val * other.der)
        return Dual(self.val * other, self.der * other)

    __rmul__ = __mul__

    def __truediv__(self, other):
        if isinstance(other, Dual):
            return self * other._reciprocal()
        return Dual(self.val / other, self.der / other)

    def __rtruediv__(self, other):
        return self._reciprocal() * other

    def _reciprocal(self):
        r = 1.0 / self.val
        return Dual(r, -self.der * (r * r))

    def __pow__(self, p):
        if p == 2:
            return self * self
        return Dual(self.val**p, self.der * (p * self.val ** (p - 1)))

    def __getitem__(self, index):
        if not (isinstance(index, tuple) and index and index[0] is Ellipsis):
            raise TypeError("index a Dual as x[..., k] so that direction axes pass through")
        return Dual(self.val[index], self.der[index])

    @property
    def shape(self):
        return np.shape(value(self))

    def __lt__(self, other):
        return value(self) < value(other)

    def __gt__(self, other):
        return value(self) > value(other)

    def __le__(self, other):
        return value(self) <= value(other)

    def __ge__(self, other):
        return value(self) >= value(other)

    # -- numpy protocol -----------------------------------------------------
    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        if method != "__call__" or kwargs:
            return NotImplemented
        rule = _UFUNCS.get(ufunc)
        if rule is None:
            raise TypeError(f"pin_susp.maths.jet.Dual does not support numpy.{ufunc.__name__}")
        return rule(*inputs)

    def __array_function__(self, func, types, args, kwargs):
        rule = _FUNCTIONS.get(func)
        if rule is None:
            raise TypeError(f"pin_susp.maths.jet.Dual does not support {func.__name__}")
        return rule(*args, **kwargs)


def value(x):
    """The plain value under any nesting of Duals."""
    while isinstance(x, Dual):
        x = x.val
    return x


def _split(x):
    return (x.val, x.der) if isinstance(x, Dual) else (x, 0.0)


def _arctan2(y, x):
    yv, yd = _split(y)
    xv, xd = _split(x)
    return Dual(np.arctan2(yv, xv), (xv * yd - yv * xd) / (xv * xv + yv * yv))


def _sqrt(x):
    r = np.sqrt(x.val)
    return Dual(r, x.der / (2.0 * r))


def _sign(x):
    return np.sign(x.val)


def _absolute(x):
    return Dual(np.abs(x.val), x.der * np.sign(value(x.val)))


def _arctan(x):
    return Dual(np.arctan(x.val), x.der / (1.0 + x.val * x.val))


def _isnan(x):
    return np.isnan(value(x))


def _compare(op):
    return lambda a, b: op(value(a), value(b))


_UFUNCS = {
    np.add: lambda a, b: a + b if isinstance(a, Dual) else b + a,
    np.subtract: lambda a, b: a - b if isinstance(a, Dual) else -(b - a),
    np.multiply: lambda a, b: a * b if isinstance(a, Dual) else b * a,
    np.true_divide: lambda a, b: a / b if isinstance(a, Dual) else b.__rtruediv__(a),
    np.negative: lambda a: -a,
    np.square: lambda a: a * a,
    np.sqrt: _sqrt,
    np.arctan2: _arctan2,
    np.arctan: _arctan,
    np.absolute: _absolute,
    np.sign: _sign,
    np.isnan: _isnan,
    np.isfinite: lambda a: np.isfinite(value(a)),
    np.less: _compare(np.less),
    np.greater: _compare(np.greater),
    np.less_equal: _compare(np.less_equal),
    np.greater_equal: _compare(np.greater_equal),
}


def _sum(x, axis=None, keepdims=False):
    if axis is None or axis >= 0:
        raise TypeError("sum a Dual over axis=-1 (or another negative axis)")
    xv, xd = _split(x)
    return Dual(np.sum(xv, axis=axis, keepdims=keepdims), np.sum(xd, axis=axis, keepdims=keepdims))


def _cross(a, b):
    av, ad = _split(a)
    bv, bd = _split(b)
    der = 0.0  # a plain factor's derivative is the scalar 0: no term
    if not isinstance(ad, float):
        der = der + cross(ad, bv)
    if not isinstance(bd, float):
        der = der + cross(av, bd)
    return Dual(cross(av, bv), der)


def cross(a, b) -> np.ndarray:
    """a × b over the last axis (length 3), broadcast as np.cross — written out by
    component: np.cross's axis handling costs more than the product on small arrays."""
    if isinstance(a, Dual) or isinstance(b, Dual):  # nested jets (sensitivities)
        return _cross(a, b)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(np.shape(a), np.shape(b)))
    np.subtract(a1 * b2, a2 * b1, out=out[..., 0])
    np.subtract(a2 * b0, a0 * b2, out=out[..., 1])
    np.subtract(a0 * b1, a1 * b0, out=out[..., 2])
    return out


def _norm(x, axis=None, keepdims=False):
    if axis is None:
        raise TypeError("take the norm of a Dual over axis=-1")
    return np.sqrt(_sum(x * x, axis=axis, keepdims=keepdims))


def _where(cond, a, b):
    cond = value(cond)
    av, ad = _split(a)
    bv, bd = _split(b)
    return Dual(np.where(cond, av, bv), np.where(cond, ad, bd))


_FUNCTIONS = {
    np.sum: _sum,
    np.cross: _cross,
    np.linalg.norm: _norm,
    np.where: _where,
}


def plain_der(x):
    """The driver-level derivative array of a (possibly nested) Dual."""
    while isinstance(x.val, Dual):
        x = x.val
    return x.der


def rate(x, i: int):
    """The rate of x along driver ``i``, kept as the same kind of object.

    The drivers (hub z, rack) are the innermost level of the points a sweep
    or a sensitivity computes: ``Dual(position, rates)`` with rates (k, n, 3),
    or, for hardpoint sensitivities, that inside a Dual over hardpoints whose
    derivative part is ``Dual(d position/dh (n_h, 1, n, 3), d rates/dh (n_h, k,
    n, 3))``. The result has the same nesting, its value the rate along driver
    i; the rate's own change along the drivers (a second derivative) is not
    known and is NaN. A plain array has no rates: NaN.
    """
    if not isinstance(x, Dual) or i >= np.shape(plain_der(x))[0]:  # no such driver
        return np.full(np.shape(value(x)), np.nan)
    if isinstance(x.val, Dual):
        outer = x.der
        return Dual(
            rate(x.val, i), Dual(outer.der[:, i : i + 1], np.full(np.shape(outer.der), np.nan))
        )
    return Dual(x.der[i], np.full(np.shape(x.der), np.nan))
