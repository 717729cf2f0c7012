"""Throughput and scaling benchmarks (see benchmarks/README.md); installed as ``wheelsoil.benchmarks``."""
