"""Kernel matrix entry by entry, in plain Python loops."""

import math

import numpy as np

from solutions.pca import *  # noqa: F401,F403


def kernel_matrix(x, y, kernel="gaussian", beta=1.0, degree=2):
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if kernel not in ("linear", "polynomial", "gaussian", "laplacian"):
        raise ValueError(f"unknown kernel {kernel!r}")
    if kernel in ("gaussian", "laplacian") and not beta > 0:
        raise ValueError("beta must be positive")
    out = np.empty((len(x), len(y)))
    for i in range(len(x)):
        for j in range(len(y)):
            if kernel == "linear":
                out[i, j] = sum(a * b for a, b in zip(x[i], y[j]))
            elif kernel == "polynomial":
                out[i, j] = (1.0 + sum(a * b for a, b in zip(x[i], y[j]))) ** degree
            elif kernel == "gaussian":
                out[i, j] = math.exp(-beta * sum((a - b) ** 2 for a, b in zip(x[i], y[j])))
            else:
                out[i, j] = math.exp(-beta * sum(abs(a - b) for a, b in zip(x[i], y[j])))
    return out
