#version 330 core
// Depth only (colour writes are masked while it draws).
void main() {}
