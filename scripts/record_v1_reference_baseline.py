"""Record the scipy reference's version-1 metrics for the 19 paper cases (run once, before the restructuring; see record_v1_baseline.py)."""
import json, sys, subprocess, time
sys.path.insert(0, "scripts")
from record_v1_baseline import paper_cases, hexed
from validation.reference import solve_reference
out = {"recorded_from_commit": subprocess.run(["git","rev-parse","HEAD"],capture_output=True,text=True).stdout.strip(),
       "rtol": 1e-10, "atol": 1e-12, "cases": {}}
t0 = time.perf_counter()
for name, scene in paper_cases():
    r = solve_reference(scene, 10.0)
    m = r.metrics()
    rec = {k: hexed(m[k]) for k in ("max_barrel_displacement","time_of_max_barrel_displacement","peak_contact_force",
           "time_of_peak_contact_force","max_absorber_velocity","time_of_max_absorber_velocity")}
    rec["impacts"] = [[hexed(i["start"]), hexed(i["end"]), hexed(i["peak_force"]), hexed(i["time_of_peak"])] for i in m["impacts"]]
    rec["dissipated_energy"] = {k: hexed(v) for k, v in m["dissipated_energy"].items()}
    out["cases"][name] = rec
    print(name, time.perf_counter()-t0, flush=True)
open("tests/data/v1_reference_baseline.json","w").write(json.dumps(out, indent=1, sort_keys=True)+"\n")
