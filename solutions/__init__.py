"""Reference implementations of the graded exercises (instructors only).

Same module and function names as the stubs in :mod:`pcl_course`. This
package is not part of the student release.
"""
