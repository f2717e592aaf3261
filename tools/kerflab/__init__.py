"""kerflab: engineering studies on kerf.fmu (virtual LCM, calibration, sweeps).

* `kerflab.lcm`       a virtual linear cutting machine: sequential passes on a
                      rock block, the LCM report table (one row per spacing and
                      penetration);
* `kerflab.calibrate` fits model constants to measured LCM rows with the
                      virtual LCM (scipy least squares, Jacobian-based confidence);
* `kerflab.sweep`     parameter studies over many FMU runs on Dask, resumable.

Everything goes through kerf.fmu with fmpy (tools/kerfhost.py): a black box.
"""
