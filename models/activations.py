"""The activation functions, written once; `models.jax.mlp` and `models.torch.mlp` translate them.

  softplus  log(1 + e^x)  (computed as logaddexp(x, 0) in both frameworks: stable, smooth)
  relu      max(x, 0)     (second derivative zero: an LNN cannot learn with it; the paper's point)
  relu2     max(x, 0)^2
  relu3     max(x, 0)^3
  tanh      tanh(x)
  sigmoid   1 / (1 + e^-x)
"""
ACTIVATIONS = ("softplus", "relu", "relu2", "relu3", "tanh", "sigmoid")
