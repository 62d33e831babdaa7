"""``battgen report``: a flight's battery at a glance, as one self-contained HTML page (or PNG images).

:mod:`.series` reads any log or capture battgen reads into time series per battery instance, through the
shared battery concepts (SI units); :mod:`.figures` computes what people compute by hand (charge and energy
used, power, minimum voltages, time under thresholds, voltage sag and internal resistance from load steps);
:mod:`.downsample` keeps long logs responsive; :mod:`.page` lays out the plotly page and :mod:`.fleet` the
page over many flights; :mod:`.png` writes static images with matplotlib.
"""
