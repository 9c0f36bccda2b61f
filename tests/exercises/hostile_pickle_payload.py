"""Hostile: the answer is an object whose unpickling runs code (``__reduce__``): were it
unpickled in the checker, it would write a marker file and make every later comparison pass.
Expected: the answer is not numbers, the task FAILED (``not_numbers``), no marker anywhere, and
a wrong file checked after it still fails."""


def _pwn(marker):
    with open(marker, "w") as f:
        f.write("the checker unpickled a student's object\n")
    compare = __import__("meshlap" + "_core.exercises.compare", fromlist=["x"])  # rewritten

    for key in compare.COMPARE:
        compare.COMPARE[key] = lambda *a, **k: compare.Comparison(True)


class Payload:
    def __reduce__(self):
        return (_pwn, ("/tmp/meshlap_hostile_pickle_ran",))

    def __array__(self, dtype=None, copy=None):  # offered as an array: still an object
        raise TypeError("not an array")


def uniform_laplacian(V, F):
    return Payload()


def barycentric_areas(V, F):
    return [Payload() for _ in range(len(V))]
