"""Projects the raw new kernel rows, without centring them."""

from solutions.pca import *  # noqa: F401,F403
from solutions.pca import kernel_matrix

MISTAKE = "no_centring"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kernel_pca_transform(new_points, points, alphas, kernel="gaussian", beta=1.0, degree=2):
    return kernel_matrix(new_points, points, kernel, beta, degree) @ alphas
