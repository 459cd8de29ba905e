"""Scene -> symbolic DAE (:class:`~daeclear.assembly.dae_model.DAEModel`): the parameter table, the
symbolic helpers, the joints' contact builders (revolute and translational clearance, the shared
contact-pair machinery) and the contact automaton.
"""
