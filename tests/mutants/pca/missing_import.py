"""A PCA written without `import numpy as np` (the module's own code uses np)."""

from solutions.pca import kernel_matrix, kernel_pca, kernel_pca_transform  # noqa: F401

MISTAKE = "same_error_everywhere"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def pca(points, correlation=False, sort=True):
    x = np.asarray(points, dtype=float)  # noqa: F821
    centred = x - x.mean(axis=0)
    eigenvalues, eigenvectors = np.linalg.eigh(centred.T @ centred / len(x))  # noqa: F821
    return eigenvalues[::-1], eigenvectors[:, ::-1]
