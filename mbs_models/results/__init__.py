"""Results of a run: :class:`~.result.Result`, post-processing of the samples, refined peaks, plots.

Needs no Exudyn (plots need matplotlib).
"""
