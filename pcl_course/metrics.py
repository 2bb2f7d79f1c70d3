"""Exercises: evaluation metrics."""


def chamfer_distance(a, b):
    """Chamfer distance between two point sets.

    ``mean_{x in a} min_{y in b} ||x - y||^2 + mean_{y in b} min_{x in a} ||x - y||^2``
    (squared distances, both directions summed, no 1/2).

    Returns
    -------
    distance : float
    """
    raise NotImplementedError("chamfer_distance: not implemented yet")


def depth_metrics(pred, gt):
    """KITTI depth-completion metrics.

    Over the pixels with ``gt > 0``, depths in metres.

    Returns
    -------
    metrics : dict
        ``rmse`` and ``mae`` in millimetres, ``irmse`` and ``imae`` in 1/km.
    """
    raise NotImplementedError("depth_metrics: not implemented yet")
