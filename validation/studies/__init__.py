"""Studies that use both the engine (:mod:`mbs_models`) and the independent reference (:mod:`validation.reference`).

* :mod:`.compare` -- engine vs reference on one scene (``recoil validate``);
* :mod:`.guarantee` -- the tolerances the documentation guarantees per accuracy preset, and the checks behind them;
* :mod:`.report` -- the replication report (``recoil paper``), with :mod:`.conventions`, :mod:`.calibration`,
  :mod:`.claims` and the paper's published numbers (:mod:`.paper`);
* :mod:`.precision` -- the work-precision study (``recoil precision``).
"""
