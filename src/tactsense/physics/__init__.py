"""The forward model: contact -> strain -> capacitance -> counts."""
