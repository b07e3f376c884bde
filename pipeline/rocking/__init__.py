"""Rigid rectangular block (or cylinder) rocking in a plane: the reference the YADE model
is verified against.  Housner's constants and closed forms (:mod:`.housner`), his
equation integrated event by event (:mod:`.response`), one-sine pulses
(:mod:`.pulse`), many blocks under sampled ground accelerations at once
(:mod:`.sampled`), recorded free-rocking decays read (:mod:`.decay`) and the rigid
frame of identical columns under a beam (:mod:`.frame`), integrated as a
:class:`~.housner.RockingBody` like a block.  SI units;
angles in rad, x = East."""
